// The bundle fit of the non-central model (Ceres): lens intrinsics, lens-to-vertex
// distance m, mirror tilt and decenter, mirror shape and one target pose per view,
// minimising the exact non-central reprojection error in pixels with a robust loss.
//
// Parameter blocks: "lens", "m", "tilt" (2), "decenter" (2), "shape" (the profile's
// parameters; none for a tabulated mirror), and per view a pose (rotation on Ceres'
// EigenQuaternionManifold, translation). Any block can be held constant.
//
// What the data can and cannot observe (gauge): with a pinhole lens every block is
// observable from targets at known metric size, the mirror's size and m through the
// parallax of near targets (far targets alone make them nearly degenerate; the reported
// standard deviations then say so). An orthographic lens makes m unobservable (it only
// shifts everything along the axis) and decenter equivalent to the principal point, and
// leaves one scale free (pixel scale x mirror size); FitOptions::DefaultsFor fixes m,
// decenter and the lens scale for it. A spherical mirror turned about its own centre is
// the same surface, so its tilt is not observable (its centre is): the defaults fix it.
// A free polynomial mirror and the lens's radial distortion bend the same radial mapping:
// the defaults hold k1, k2 and let the mirror shape absorb them.
//
// The pieces: the options (calib/fit_options.h), the cost (calib/reprojection_cost.h),
// the blocks packed from the registry (calib/sensor_blocks.h), the covariance
// (calib/fit_covariance.h). The stages, in order: the poses alone through the guess;
// everything but the distortion; everything asked for; (robust mode) outliers and
// ill-fitting views removed, then a Huber solve; the priors re-weighted to the final noise;
// the covariance.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "calib/detections.h"
#include "calib/fit_options.h"
#include "calib/target.h"
#include "model/parameter_field.h"
#include "model/progress.h"
#include "model/sensor.h"

namespace ceres {
class CostFunction;
}

namespace omnical {

struct TargetPose {
  Eigen::Quaterniond camera_from_target_rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d camera_from_target_translation_mm = Eigen::Vector3d::Zero();
};

struct ParameterEstimate {
  std::string name;  // with its unit: fx_px, m_mm, tilt_x_deg, ...
  double value = 0.0;
  double std = 0.0;  // from (J^T J)^-1 scaled by the residual variance; 0 if fixed, NaN if undetermined
  bool fixed = false;
  ParameterGroup group = ParameterGroup::kShape;  // which refine switch moves it
  bool scale_like = false;                        // model/parameter_field.h
};

struct FitResult {
  std::optional<Sensor> sensor;  // its rim enlarged, if needed, to enclose every fitted corner's reflection
  std::vector<TargetPose> poses;
  std::vector<ParameterEstimate> parameters;
  double rms_px = 0.0;  // per corner, over the inliers
  std::vector<double> per_view_rms_px;
  // Per view: the weight its corners' residuals were multiplied by (FitOptions::
  // view_noise_weights: pooled sigma / the view's sigma); NaN for a view left out; empty
  // when not weighted.
  std::vector<double> per_view_weight;
  // Residual (observed - predicted... as fitted: predicted - observed) per view, per corner
  // in the order of the detections; NaN where the corner was dropped.
  std::vector<std::vector<Eigen::Vector2d>> residuals_px;
  int outliers = 0;  // gross outliers removed (robust mode, see FitOptions)
  std::vector<int> per_view_outliers;
  double outlier_threshold_px = 0.0;  // the |residual| beyond which corners were removed (0: none)
  int dropped = 0;   // observations not projectable at the initial guess
  int observations = 0;
  // Per view: empty if the view was fitted, else why it was left out (too few corners
  // projectable at the guess, or left after outlier removal). A left-out view's pose is
  // not estimated and its per-view RMS is NaN; it never makes the covariance singular.
  std::vector<std::string> view_left_out;
  bool converged = false;
  std::string solver_report;
  bool covariance_ok = false;
  // The covariance of the free sensor parameters (poses marginalised: their coupling is
  // in it), in the units of `parameters`, rows in the order of covariance_names.
  Eigen::MatrixXd covariance;
  std::vector<std::string> covariance_names;
  Eigen::MatrixXd correlation;  // of the covariance, same order
  // Residual blocks and parameter blocks in the final problem (after outlier removal and
  // gauge fixing): corners fitted, priors, and the blocks Ceres moved (poses included).
  int residual_blocks = 0;
  int free_parameter_blocks = 0;
  int free_columns = 0;  // tangent-space size of those blocks
  // Parameters that ended more than 3 tolerances from their design values, one line each.
  std::vector<std::string> tolerance_conflicts;
  // How the tolerances were applied where that is not as given (ignored on a held
  // parameter, folded into another), one line each.
  std::vector<std::string> tolerance_notes;
  // A spline's c1 where the covariance holds it at its fitted value (a near-gauge of the
  // knots: calib/bundle_fit.cc): its std as a share of its value before; NaN otherwise.
  // `parameters` then report it free with a NaN std, and the covariance leaves it out.
  double vertex_curvature_std_ratio = NAN;
  double guess_rim_radius_mm = 0.0;  // the guess's rim, for comparison with the fitted sensor's
  // Corner residuals' standard deviation per coordinate (px), from the fit's RMS and its
  // degrees of freedom: what the covariance is scaled by. With per-view weights, that of
  // a unit-weight corner (the weighted residuals').
  double sigma_px = 0.0;
  // The board's warp when FitOptions::fit_board_warp (its std from the same covariance).
  std::optional<BoardWarpEstimate> board_warp;
};

// The sensor's parameters in FitResult's naming and units (values only, std 0), with
// their groups.
std::vector<ParameterEstimate> SensorParameters(const Sensor& sensor);
// Tolerances per parameter name: the pairs (tilt_deg, decenter_mm, principal_point_px,
// focal_px) expanded to their components, a component named on its own winning.
std::map<std::string, double> ExpandTolerances(const std::map<std::string, double>& tolerances);

// The sensor with its rim `factor` times as wide, within the profile's domain: for
// evaluating corners the fit let stray past the rim, or parameter steps near it.
Sensor SensorWithWiderRim(const Sensor& sensor, double factor);

// The sensor with its rim up to `max_factor` times as wide, as far as it stays a valid
// sensor (1 % inside the limit; the sensor unchanged if it is not valid itself): where
// the fitted model still predicts, past the corners it was fitted on.
Sensor SensorWithWidestValidRim(const Sensor& sensor, double max_factor);

// The sensor with its parameters set to `values` (SensorParameters' order and units).
Sensor SensorWithParameters(const Sensor& sensor, const std::vector<double>& values);

// The target's pose in a view from its detections through a sensor: rays of the detected
// pixels, a central approximation at their mean origin, then PnP (OpenCV) on the bearing
// vectors. A start for FitSensor, accurate to the sensor's parallax.
bool InitialTargetPose(const Sensor& sensor, const CalibrationTarget& target, const ImageDetections& image,
                       TargetPose* pose);

// The board's warp a fit ran with: fitted, else the one `options` held.
inline BoardWarp WarpOf(const FitResult& fit, const FitOptions& options) {
  return fit.board_warp ? fit.board_warp->warp : options.board_warp;
}

// Fits from `guess` and the initial poses (one per detections.images entry).
FitResult FitSensor(const Sensor& guess, const CalibrationTarget& target, const DetectionSet& detections,
                    const std::vector<TargetPose>& initial_poses, const FitOptions& options);

// The fit's cost of one corner (calib/reprojection_cost.h) for the model's type, without
// the warp block; the caller owns it. Its automatic derivatives are compiled here, once,
// instead of again in each caller (they took a test ~30 s to compile).
ceres::CostFunction* CreateReprojectionCost(const SensorModel& model, const Eigen::Vector3d& point_in_target_mm,
                                            const Eigen::Vector2d& observed_px);

}  // namespace omnical

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
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "calib/detections.h"
#include "calib/target.h"
#include "model/progress.h"
#include "model/sensor.h"

namespace omnical {

struct FitOptions {
  std::set<std::string> fixed;  // block names: lens, lens_scale, distortion (k1, k2), m, tilt, decenter, shape, poses
  double robust_loss_px = 1.0;  // robust scale in px (Cauchy, outlier removal, then Huber); 0 = plain least squares
  int max_iterations = 200;
  bool compute_covariance = true;
  // Outliers (robust mode): |residual| beyond max(outlier_floor_px, outlier_sigmas x a
  // robust sigma of the residuals) are removed. The floor keeps a very good fit (renders:
  // 0.02 px) from throwing good corners away; 4 sigma of a 2-D Gaussian's |e| cuts 3e-4.
  double outlier_floor_px = 0.5;
  double outlier_sigmas = 4.0;
  // A view whose inlier RMS exceeds max(outlier_floor_px, view_rms_ratio x the median of
  // the views' RMS) is left out (robust mode): it shows something else than the other
  // views' board. Real views differ by up to 2.5x (measured on the dev set).
  double view_rms_ratio = 4.0;
  // Design tolerances: one standard deviation of a Gaussian prior around the guess's value,
  // per parameter name as FitResult names them (fx_px, cx_px, k1, m_mm, decenter_x_mm,
  // A_mm, ...) or a pair: tilt_deg, decenter_mm, principal_point_px, focal_px. They pull
  // the fit towards the design (a weak prior residual: the wrong basins of the camera
  // rotation / decenter / distortion valley lie many tolerances away) and enter the
  // covariance. A tolerance on a held parameter is ignored (FitResult::tolerance_notes
  // says so); on a sphere with its tilt held, a tilt tolerance widens the decenter's.
  std::map<std::string, double> tolerances;
  // The design values the tolerances are centred on, by parameter name (reported units);
  // a parameter not named here is centred on the guess's value. A pipeline that fits
  // several times (a second detection pass from the first fit) keeps the user's design.
  std::map<std::string, double> design;
  // Stage "fit", one step per solver iteration; returning false cancels (Cancelled).
  ProgressCallback progress;

  // The gauge-fixing defaults for a sensor (see above).
  static FitOptions DefaultsFor(const Sensor& sensor);
  // Empty if valid, else "field: problem".
  std::string Check() const;
  // Check() and the tolerance names against the sensor's parameters ("tolerances.x: ...").
  std::string CheckFor(const Sensor& sensor) const;
};

struct TargetPose {
  Eigen::Quaterniond camera_from_target_rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d camera_from_target_translation_mm = Eigen::Vector3d::Zero();
};

struct ParameterEstimate {
  std::string name;  // with its unit: fx_px, m_mm, tilt_x_deg, ...
  double value = 0.0;
  double std = 0.0;  // from (J^T J)^-1 scaled by the residual variance; 0 if fixed, NaN if undetermined
  bool fixed = false;
};

struct FitResult {
  std::optional<Sensor> sensor;  // its rim enlarged, if needed, to enclose every fitted corner's reflection
  std::vector<TargetPose> poses;
  std::vector<ParameterEstimate> parameters;
  double rms_px = 0.0;  // per corner, over the inliers
  std::vector<double> per_view_rms_px;
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
  // Parameters that ended more than 3 tolerances from their design values, one line each.
  std::vector<std::string> tolerance_conflicts;
  // How the tolerances were applied where that is not as given (ignored on a held
  // parameter, folded into another), one line each.
  std::vector<std::string> tolerance_notes;
  double guess_rim_radius_mm = 0.0;  // the guess's rim, for comparison with the fitted sensor's
  // Corner residuals' standard deviation per coordinate (px), from the fit's RMS and its
  // degrees of freedom: what the covariance is scaled by.
  double sigma_px = 0.0;
};

// The sensor's parameters in FitResult's naming and units (values only, std 0).
std::vector<ParameterEstimate> SensorParameters(const Sensor& sensor);
// Tolerances per parameter name: the pairs (tilt_deg, decenter_mm, principal_point_px,
// focal_px) expanded to their components, a component named on its own winning.
std::map<std::string, double> ExpandTolerances(const std::map<std::string, double>& tolerances);

// The sensor with its rim `factor` times as wide, within the profile's domain: for
// evaluating corners the fit let stray past the rim, or parameter steps near it.
Sensor SensorWithWiderRim(const Sensor& sensor, double factor);

// The sensor with its parameters set to `values` (SensorParameters' order and units).
Sensor SensorWithParameters(const Sensor& sensor, const std::vector<double>& values);

// The target's pose in a view from its detections through a sensor: rays of the detected
// pixels, a central approximation at their mean origin, then PnP (OpenCV) on the bearing
// vectors. A start for FitSensor, accurate to the sensor's parallax.
bool InitialTargetPose(const Sensor& sensor, const CalibrationTarget& target, const ImageDetections& image,
                       TargetPose* pose);

// Fits from `guess` and the initial poses (one per detections.images entry).
FitResult FitSensor(const Sensor& guess, const CalibrationTarget& target, const DetectionSet& detections,
                    const std::vector<TargetPose>& initial_poses, const FitOptions& options);

}  // namespace omnical

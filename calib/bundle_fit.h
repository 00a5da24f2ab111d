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
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "calib/detections.h"
#include "calib/target.h"
#include "model/sensor.h"

namespace omnical {

struct FitOptions {
  std::set<std::string> fixed;  // block names: lens, lens_scale, distortion (k1, k2), m, tilt, decenter, shape, poses
  double robust_loss_px = 1.0;  // robust scale in px (Cauchy, outlier removal, then Huber); 0 = plain least squares
  int max_iterations = 200;
  bool compute_covariance = true;

  // The gauge-fixing defaults for a sensor (see above).
  static FitOptions DefaultsFor(const Sensor& sensor);
  // Empty if valid, else "field: problem".
  std::string Check() const;
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
  std::optional<Sensor> sensor;
  std::vector<TargetPose> poses;
  std::vector<ParameterEstimate> parameters;
  double rms_px = 0.0;  // per corner, over the inliers
  std::vector<double> per_view_rms_px;
  // Residual (observed - predicted... as fitted: predicted - observed) per view, per corner
  // in the order of the detections; NaN where the corner was dropped.
  std::vector<std::vector<Eigen::Vector2d>> residuals_px;
  int outliers = 0;  // gross outliers removed (robust mode: beyond 5 sigma from the median residual)
  int dropped = 0;   // observations not projectable at the initial guess
  int observations = 0;
  bool converged = false;
  std::string solver_report;
  bool covariance_ok = false;
};

// The sensor's parameters in FitResult's naming and units (values only, std 0).
std::vector<ParameterEstimate> SensorParameters(const Sensor& sensor);

// The target's pose in a view from its detections through a sensor: rays of the detected
// pixels, a central approximation at their mean origin, then PnP (OpenCV) on the bearing
// vectors. A start for FitSensor, accurate to the sensor's parallax.
bool InitialTargetPose(const Sensor& sensor, const CalibrationTarget& target, const ImageDetections& image,
                       TargetPose* pose);

// Fits from `guess` and the initial poses (one per detections.images entry).
FitResult FitSensor(const Sensor& guess, const CalibrationTarget& target, const DetectionSet& detections,
                    const std::vector<TargetPose>& initial_poses, const FitOptions& options);

}  // namespace omnical

#include "calib/board_scale.h"

#include <ceres/ceres.h>

#include <cmath>
#include <cstdio>
#include <map>

namespace omnical {
namespace {

// One corner through the fixed sensor, the board scaled by exp(log_scale). Templated for
// automatic derivatives: by central differences (17 projections per corner and Jacobian)
// this check was ~40 % of a `calibrate --detections` run, more than the bundle fit.
struct ScaledCornerError {
  const Sensor* sensor;
  Eigen::Vector3d point_in_target_mm;
  Eigen::Vector2d observed_px;

  template <typename T>
  bool operator()(const T* rotation_xyzw, const T* translation_mm, const T* log_scale, T* residual) const {
    using std::exp;
    const Eigen::Quaternion<T> rotation(rotation_xyzw[3], rotation_xyzw[0], rotation_xyzw[1], rotation_xyzw[2]);
    const Vec3<T> in_camera = rotation.normalized() * (exp(log_scale[0]) * point_in_target_mm.cast<T>()) +
                              Vec3<T>(translation_mm[0], translation_mm[1], translation_mm[2]);
    // The optics only, as in the bundle fit: the corner was seen, so no image-bounds or
    // occlusion test (a step across the image border would fail the derivative).
    return std::visit(
        [&](const auto& model) {
          Vec3<T> mirror_point;
          Vec2<T> pixel;
          const auto model_t = model.template Cast<T>();
          if (model_t.ReflectionPoint(in_camera, &mirror_point, &sensor->cache()) != ProjectionStatus::kOk ||
              !model_t.lens.ProjectToPixel(mirror_point, &pixel))
            return false;
          residual[0] = pixel.x() - T(observed_px.x());
          residual[1] = pixel.y() - T(observed_px.y());
          return true;
        },
        sensor->model());
  }
};

struct Fitted {
  double sum_px2 = HUGE_VAL;  // sum of squared residuals
  double scale = 1.0, distance_mm = 0.0;
};

// The pose (and, unless held, the scale) fitted from a start `scale` times the size and
// as far; the translation scales with it, so the start looks the same through a central
// approximation.
Fitted FitAtScale(const std::vector<ScaledCornerError>& corners, const TargetPose& pose,
                  double scale, bool hold_scale) {
  const Eigen::Quaterniond& q = pose.camera_from_target_rotation;
  double rotation[4] = {q.x(), q.y(), q.z(), q.w()};
  Eigen::Vector3d t = scale * pose.camera_from_target_translation_mm;
  double translation[3] = {t.x(), t.y(), t.z()};
  double log_scale = std::log(scale);
  Fitted fitted;
  // A start where a corner does not project is no start (and Ceres would log its failure).
  for (const ScaledCornerError& corner : corners) {
    double residual[2];
    if (!corner(rotation, translation, &log_scale, residual)) return fitted;
  }
  ceres::Problem problem;
  for (const ScaledCornerError& corner : corners)
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<ScaledCornerError, 2, 4, 3, 1>(new ScaledCornerError(corner)),
        nullptr, rotation, translation, &log_scale);
  problem.SetManifold(rotation, new ceres::EigenQuaternionManifold);
  if (hold_scale) problem.SetParameterBlockConstant(&log_scale);
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 50;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  if (!summary.IsSolutionUsable()) return fitted;
  fitted.sum_px2 = 2.0 * summary.final_cost;
  fitted.scale = std::exp(log_scale);
  fitted.distance_mm = Eigen::Vector3d(translation[0], translation[1], translation[2]).norm();
  return fitted;
}

}  // namespace

BoardScale CheckBoardScale(const Sensor& sensor, const CalibrationTarget& target, const ImageDetections& image,
                           const TargetPose& pose, double sigma_px, const BoardScaleOptions& options,
                           const BoardWarp& warp) {
  const std::map<int, Eigen::Vector3d> points = warp.CornerPoints(target);
  std::vector<ScaledCornerError> corners;
  for (const CornerObservation& c : image.corners) {
    const auto point = points.find(c.id);
    if (point != points.end()) corners.push_back({&sensor, point->second, c.pixel});
  }
  BoardScale result;
  if (corners.size() < 6 || !(sigma_px > 0.0)) return result;  // too little to tell
  // The fit lets reflections stray 15 % past the rim; so does this check.
  const Sensor wide = SensorWithWiderRim(sensor, 1.15);
  for (ScaledCornerError& corner : corners) corner.sensor = &wide;
  const Fitted at_target = FitAtScale(corners, pose, 1.0, true);
  Fitted best = at_target;
  // Starts spread over sizes (the scale's cost can have a minimum per basin): the target's,
  // a quarter and four times it.
  for (double start : {0.25, 1.0, 4.0}) {
    const Fitted fitted = FitAtScale(corners, pose, start, false);
    if (fitted.sum_px2 < best.sum_px2) best = fitted;
  }
  result.best_scale = best.scale;
  result.best_distance_mm = best.distance_mm;
  result.rms_at_target_px = std::sqrt(at_target.sum_px2 / corners.size());
  result.rms_at_best_px = std::sqrt(best.sum_px2 / corners.size());
  result.chi2_gain = (at_target.sum_px2 - best.sum_px2) / (sigma_px * sigma_px);
  const bool other_size = best.scale > options.max_size_ratio || best.scale < 1.0 / options.max_size_ratio;
  if (other_size && result.chi2_gain > options.min_chi2) {
    result.refused = true;
    char text[240];
    std::snprintf(text, sizeof text,
                  "fits as a board %.2f x the target's size at %.0f mm (RMS %.3f px, against %.3f px at the target's "
                  "size): not the calibration target",
                  best.scale, best.distance_mm, result.rms_at_best_px, result.rms_at_target_px);
    result.reason = text;
  }
  return result;
}

}  // namespace omnical

#include "calib/checkerboard_completion.h"

#include <map>
#include <set>
#include <stdexcept>

namespace omnical {

DetectionSet WithPredictedCheckerCorners(const CalibrationTarget& target, const Sensor& sensor, const BoardWarp& warp,
                                         const DetectionSet& fitted, const FitResult& fit, DetectionSet found) {
  if (target.type() != CalibrationTarget::Type::kCheckerboard) return found;
  if (fit.poses.size() != fitted.images.size() || fit.view_left_out.size() != fitted.images.size())
    throw std::logic_error("WithPredictedCheckerCorners: the fit describes other views than `fitted`");
  const std::map<int, Eigen::Vector3d> points = warp.CornerPoints(target);
  std::map<std::string, ImageDetections*> by_name;
  for (ImageDetections& image : found.images) by_name[image.image] = &image;
  for (size_t v = 0; v < fitted.images.size(); ++v) {
    if (!fit.view_left_out[v].empty()) continue;
    const auto it = by_name.find(fitted.images[v].image);
    if (it == by_name.end()) continue;
    ImageDetections& image = *it->second;
    std::set<int> have;
    for (const CornerObservation& c : image.corners) have.insert(c.id);
    const TargetPose& pose = fit.poses[v];
    for (const auto& [id, in_target] : points) {
      if (have.count(id)) continue;
      const Eigen::Vector3d in_camera =
          pose.camera_from_target_rotation * in_target + pose.camera_from_target_translation_mm;
      Eigen::Vector2d pixel;
      if (sensor.Project(in_camera, &pixel) != ProjectionStatus::kOk) continue;
      CornerObservation predicted{id, pixel};
      predicted.predicted = true;
      image.corners.push_back(predicted);
    }
  }
  return found;
}

}  // namespace omnical

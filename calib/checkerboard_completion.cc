#include "calib/checkerboard_completion.h"

#include <map>
#include <set>
#include <stdexcept>

namespace omnical {

namespace {

// The image of each kept view of `fitted` in `found` (by name), with the view's fitted pose.
template <typename PerView>
void ForEachFittedView(const DetectionSet& fitted, const FitResult& fit, DetectionSet* found, const PerView& per_view) {
  if (fit.poses.size() != fitted.images.size() || fit.view_left_out.size() != fitted.images.size())
    throw std::logic_error("WithPredicted...Corners: the fit describes other views than `fitted`");
  std::map<std::string, ImageDetections*> by_name;
  for (ImageDetections& image : found->images) by_name[image.image] = &image;
  for (size_t v = 0; v < fitted.images.size(); ++v) {
    if (!fit.view_left_out[v].empty()) continue;
    const auto it = by_name.find(fitted.images[v].image);
    if (it != by_name.end()) per_view(fit.poses[v], it->second);
  }
}

Eigen::Vector3d InCamera(const TargetPose& pose, const Eigen::Vector3d& in_target) {
  return pose.camera_from_target_rotation * in_target + pose.camera_from_target_translation_mm;
}

}  // namespace

DetectionSet WithPredictedCheckerCorners(const CalibrationTarget& target, const Sensor& sensor, const BoardWarp& warp,
                                         const DetectionSet& fitted, const FitResult& fit, DetectionSet found) {
  if (target.type() != CalibrationTarget::Type::kCheckerboard) return found;
  const std::map<int, Eigen::Vector3d> points = warp.CornerPoints(target);
  ForEachFittedView(fitted, fit, &found, [&](const TargetPose& pose, ImageDetections* image) {
    std::set<int> have;
    for (const CornerObservation& c : image->corners) have.insert(c.id);
    for (const auto& [id, in_target] : points) {
      Eigen::Vector2d pixel;
      if (have.count(id) || sensor.Project(InCamera(pose, in_target), &pixel) != ProjectionStatus::kOk) continue;
      CornerObservation predicted{id, pixel};
      predicted.predicted = true;
      image->corners.push_back(predicted);
    }
  });
  return found;
}

DetectionSet WithPredictedTagCorners(const CalibrationTarget& target, const Sensor& sensor, const BoardWarp& warp,
                                     const DetectionSet& fitted, const FitResult& fit, DetectionSet found) {
  if (target.type() != CalibrationTarget::Type::kAprilGrid) return found;
  const Sensor wider = SensorWithWiderRim(sensor, 1.15);
  std::map<int, std::map<int, Eigen::Vector3d>> tags;  // tag -> corner id -> point
  for (const auto& [id, in_target] : warp.CornerPoints(target)) tags[id / 4][id] = in_target;
  ForEachFittedView(fitted, fit, &found, [&](const TargetPose& pose, ImageDetections* image) {
    std::set<int> have;
    for (const CornerObservation& c : image->corners) have.insert(c.id);
    for (const auto& [tag, corners] : tags) {
      std::vector<CornerObservation> predicted;
      bool on_mirror = false, all_seen = true;
      for (const auto& [id, in_target] : corners) {
        Eigen::Vector2d pixel;
        on_mirror = on_mirror || sensor.Project(InCamera(pose, in_target), &pixel) == ProjectionStatus::kOk;
        if (have.count(id)) continue;
        if (wider.Project(InCamera(pose, in_target), &pixel) != ProjectionStatus::kOk) all_seen = false;
        predicted.push_back({id, pixel});
        predicted.back().predicted = true;
      }
      if (predicted.empty() || !on_mirror || !all_seen || corners.size() != 4) continue;
      image->corners.insert(image->corners.end(), predicted.begin(), predicted.end());
    }
  });
  return found;
}

}  // namespace omnical

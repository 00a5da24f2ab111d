// Synthetic views for the fit tests: a board placed around a sensor and its corners
// projected exactly by it (calib/synthetic/), with the true poses.
#pragma once

#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "calib/bundle_fit.h"
#include "calib/synthetic/ground_truth.h"
#include "calib/synthetic/scene.h"
#include "test_sensors.h"

namespace omnical::testing {

// Views of the 30 mm aprilgrid (6 x 6 tags, 144 corners) around the mirror at 2-20 mirror
// radii, each corner projected exactly by the truth.
struct Observations {
  CalibrationTarget target;
  DetectionSet detections;
  std::vector<TargetPose> poses;  // the truth's
};
inline Observations ObservationsAround(const Sensor& truth, int views, unsigned seed, double nearest_rims = 2.0,
                                       double farthest_rims = 20.0) {
  const auto board = std::make_shared<const CalibrationTarget>(
      CalibrationTarget::FromYaml(testing::SourceDir() + "/datasets-synthetic/targets/aprilgrid-6x6-30mm.yaml"));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Observations out{*board, {}, {}};
  out.detections.image_width_px = truth.image_width_px();
  out.detections.image_height_px = truth.image_height_px();
  for (int k = 0; k < views; ++k) {
    SceneView view;
    PlacedTarget placed{"board", board, "", Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), {}};
    const double distance_mm =
        kRimMm * nearest_rims * std::pow(farthest_rims / nearest_rims, static_cast<double>(k) / (views - 1));
    PlaceTarget(truth, *board, 60.0 + 50.0 * unit(rng), 360.0 * k / views + 20.0 * unit(rng), distance_mm,
                60.0 * unit(rng) - 30.0, 30.0 * unit(rng) - 15.0, 30.0 * unit(rng) - 15.0,
                &placed.camera_from_target_rotation, &placed.camera_from_target_translation_mm);
    view.name = "view" + std::to_string(k);
    view.targets.push_back(placed);
    ImageDetections image;
    image.image = view.name;
    for (const TargetTruth& t : GroundTruth(truth, view))
      for (const CornerTruth& c : t.corners)
        if (c.visible) image.corners.push_back({c.id, c.pixel});
    if (image.corners.size() < 20) continue;
    out.detections.images.push_back(image);
    TargetPose pose;
    pose.camera_from_target_rotation = Eigen::Quaterniond(placed.camera_from_target_rotation);
    pose.camera_from_target_translation_mm = placed.camera_from_target_translation_mm;
    out.poses.push_back(pose);
  }
  return out;
}

}  // namespace omnical::testing

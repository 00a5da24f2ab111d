// omnical's ray tracer: every pixel traced backwards through the lens and the mirror
// (exact model) into a scene of planar targets in an environment, with n x n stratified
// supersampling, vignetting, Gaussian defocus and sensor noise. Pixels that see no mirror
// are the dark rim; pixels that see the camera's own reflection are its dark body.
#pragma once

#include <opencv2/core.hpp>

#include <functional>
#include <vector>

#include "correction/pixel_ray_grid.h"
#include "calib/synthetic/scene.h"

namespace omnical {

// 8-bit image of one view: grey, or BGR with formation.colour. Deterministic: the noise
// comes from formation.seed and the view index, independently of the number of threads.
cv::Mat RenderView(const Sensor& sensor, const PixelRayGrid& rays, const SceneView& view,
                   const Environment& environment, const ImageFormation& formation, unsigned view_index, int threads,
                   const std::function<void(long)>& progress = nullptr);

// Ground truth of one view: every target corner's exact pixel (exact projection) and
// whether it is visible: imaged (status ok), seen from its printed side, and not hidden
// by another target. A bent board's corners lie on its surface (PlacedTarget::surface).
struct CornerTruth {
  int id;
  Eigen::Vector3d point_in_target_mm, point_in_camera_mm;
  Eigen::Vector2d pixel;
  ProjectionStatus status;
  bool visible;
};
struct TargetTruth {
  const PlacedTarget* placement;
  std::vector<CornerTruth> corners;
};
std::vector<TargetTruth> GroundTruth(const Sensor& sensor, const SceneView& view);

}  // namespace omnical

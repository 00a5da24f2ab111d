// A virtual perspective view resampled from the omni image: a pinhole camera at a point
// of the sensor (its reference viewpoint, or a ray's own origin) looking along a chosen
// frame. Each view pixel holds the projection of the point along its ray at the view's
// depth (exact on a grid of nodes, within 0.01 px between them: model/grid_table.h), so
// anything found in the view maps back to omni pixels through the same table, whatever
// the error of the sensor the view was built with.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "model/sensor.h"

namespace omnical {

class VirtualView {
 public:
  // view_to_camera: columns right, down, forward of the view in the camera frame.
  // "Infinity": far enough that the rays' origins on the mirror (mm apart) do not matter.
  static constexpr double kFarMm = 1e8;

  // The view shows the sphere of radius depth_mm around its centre: the mirror has no
  // single viewpoint, so a scene at another distance is slightly bent in it (straight
  // lines curve). The default is the scene at infinity.
  VirtualView(const Sensor& sensor, const Eigen::Matrix3d& view_to_camera, const Eigen::Vector3d& centre_in_camera_mm,
              double focal_px, int width_px, int height_px, double depth_mm = kFarMm);

  // The view of the omni image (8-bit grey), 0 where a ray misses the mirror.
  cv::Mat Resample(const cv::Mat& omni_grey, int interpolation) const;
  // View pixel of a direction from the view's centre (pixel-centre coordinates).
  Eigen::Vector2d ToView(const Eigen::Vector3d& direction_in_camera) const;
  // Direction (unit, camera frame) from the view's centre through a view pixel.
  Eigen::Vector3d Direction(const Eigen::Vector2d& view_px) const;
  // View pixel of an omni pixel: Newton steps on the table from `start_view_px` (e.g.
  // ToView of the pixel's ray direction, which the mirror's parallax puts a little off);
  // false when they leave the view or do not converge to 0.01 px.
  bool FromOmni(const Eigen::Vector2d& omni_px, const Eigen::Vector2d& start_view_px, Eigen::Vector2d* view_px) const;
  // Omni pixel of a view pixel, bilinear in the table; false outside the view or next to
  // a ray that missed.
  bool ToOmni(const Eigen::Vector2d& view_px, Eigen::Vector2d* omni_px) const;

  int width_px() const { return map_x_.cols; }
  int height_px() const { return map_x_.rows; }

 private:
  Eigen::Matrix3d view_to_camera_;
  double focal_px_;
  cv::Mat map_x_, map_y_;  // CV_32F omni pixel per view pixel; -1 where the ray misses
};

// A square view looking along a camera-frame direction from the sensor's reference
// viewpoint on the axis (its axial analysis), image "down" towards the mirror's -z.
VirtualView ViewAlong(const Sensor& sensor, const Eigen::Vector3d& forward_in_camera, int size_px, double focal_px);

// Right-handed view frame (right, down, forward) looking along `forward`, with image "down"
// as close as possible to `down_hint`.
Eigen::Matrix3d ViewFrame(const Eigen::Vector3d& forward, const Eigen::Vector3d& down_hint);

}  // namespace omnical

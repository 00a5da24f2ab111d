#include "calib/virtual_view.h"

#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <vector>

#include "calib/bilinear.h"
#include "model/grid_table.h"

namespace omnical {

VirtualView::VirtualView(const Sensor& sensor, const Eigen::Matrix3d& view_to_camera,
                         const Eigen::Vector3d& centre_in_camera_mm, double focal_px, int width_px, int height_px, double depth_mm)
    : view_to_camera_(view_to_camera), focal_px_(focal_px) {
  const double cx = 0.5 * (width_px - 1), cy = 0.5 * (height_px - 1);
  // Exact on a grid of nodes, cubic between them, cells checked (model/grid_table.h): a
  // view of a few hundred pixels across needs ~50 x fewer projections than pixels, and
  // the views were most of a detection's time when every pixel was projected.
  GridTableRequest request;
  request.width = width_px;
  request.height = height_px;
  request.step_px = NodeStepPx(1.0 / focal_px);
  request.project = [&](const Eigen::Matrix2Xd& view_points) {
    Eigen::Matrix3Xd points(3, view_points.cols());
    for (Eigen::Index k = 0; k < view_points.cols(); ++k)
      points.col(k) = centre_in_camera_mm +
                      depth_mm * (view_to_camera * Eigen::Vector3d((view_points(0, k) - cx) / focal_px,
                                                                   (view_points(1, k) - cy) / focal_px, 1.0)).normalized();
    Eigen::Matrix2Xd pixels;
    std::vector<ProjectionStatus> statuses;
    sensor.ProjectBatch(points, &pixels, &statuses);
    for (Eigen::Index k = 0; k < view_points.cols(); ++k)
      if (statuses[k] != ProjectionStatus::kOk) pixels.col(k).setConstant(NAN);
    return pixels;
  };
  map_x_.create(height_px, width_px, CV_32F);
  map_y_.create(height_px, width_px, CV_32F);
  map_x_.setTo(-1.0f);
  map_y_.setTo(-1.0f);
  FillGridTable(request, map_x_.ptr<float>(), map_y_.ptr<float>());
}

cv::Mat VirtualView::Resample(const cv::Mat& omni_grey, int interpolation) const {
  cv::Mat view;
  cv::remap(omni_grey, view, map_x_, map_y_, interpolation, cv::BORDER_CONSTANT, cv::Scalar(0));
  return view;
}

Eigen::Vector2d VirtualView::ToView(const Eigen::Vector3d& direction_in_camera) const {
  const Eigen::Vector3d in_view = view_to_camera_.transpose() * direction_in_camera;
  return Eigen::Vector2d(focal_px_ * in_view.x() / in_view.z() + 0.5 * (width_px() - 1),
                         focal_px_ * in_view.y() / in_view.z() + 0.5 * (height_px() - 1));
}

Eigen::Vector3d VirtualView::Direction(const Eigen::Vector2d& view_px) const {
  const Eigen::Vector3d in_view((view_px.x() - 0.5 * (width_px() - 1)) / focal_px_,
                                (view_px.y() - 0.5 * (height_px() - 1)) / focal_px_, 1.0);
  return (view_to_camera_ * in_view).normalized();
}

bool VirtualView::ToOmni(const Eigen::Vector2d& view_px, Eigen::Vector2d* omni_px) const {
  const double x = view_px.x(), y = view_px.y();
  const double u = Bilinear<float>(map_x_, x, y), v = Bilinear<float>(map_y_, x, y);
  if (!std::isfinite(u) || !std::isfinite(v)) return false;
  // A neighbour whose ray missed the mirror holds -1: no omni pixel there.
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  for (int dy = 0; dy < 2; ++dy)
    for (int dx = 0; dx < 2; ++dx)
      if (map_x_.at<float>(y0 + dy, x0 + dx) < 0.0f) return false;
  *omni_px = Eigen::Vector2d(u, v);
  return true;
}

bool VirtualView::FromOmni(const Eigen::Vector2d& omni_px, const Eigen::Vector2d& start_view_px,
                           Eigen::Vector2d* view_px) const {
  Eigen::Vector2d at = start_view_px;
  constexpr double kStepPx = 0.5;  // finite differences across the bilinear table
  for (int iteration = 0; iteration < 20; ++iteration) {
    Eigen::Vector2d here, right, below;
    if (!ToOmni(at, &here) || !ToOmni(at + Eigen::Vector2d(kStepPx, 0), &right) ||
        !ToOmni(at + Eigen::Vector2d(0, kStepPx), &below))
      return false;
    Eigen::Matrix2d jacobian;
    jacobian << (right - here) / kStepPx, (below - here) / kStepPx;
    if (std::abs(jacobian.determinant()) < 1e-12) return false;
    const Eigen::Vector2d step = jacobian.inverse() * (omni_px - here);
    at += step;
    if (step.norm() < 0.01) {
      *view_px = at;
      return ToOmni(at, &here);
    }
  }
  return false;
}

VirtualView ViewAlong(const Sensor& sensor, const Eigen::Vector3d& forward_in_camera, int size_px, double focal_px) {
  const ProjectionCache& cache = sensor.cache();
  const double viewpoint_z = cache.guess.valid() ? cache.guess.reference_viewpoint_mm() : 0.0;
  const Eigen::Vector3d centre = cache.camera_from_mirror_rotation * Eigen::Vector3d(0, 0, viewpoint_z) +
                                 cache.camera_from_mirror_translation;
  const Eigen::Vector3d down = cache.camera_from_mirror_rotation * -Eigen::Vector3d::UnitZ();
  return VirtualView(sensor, ViewFrame(forward_in_camera, down), centre, focal_px, size_px, size_px);
}

Eigen::Matrix3d ViewFrame(const Eigen::Vector3d& forward, const Eigen::Vector3d& down_hint) {
  const Eigen::Vector3d f = forward.normalized();
  Eigen::Vector3d right = down_hint.cross(f);  // then f x right is down_hint's part across f
  if (right.norm() < 1e-9) right = f.unitOrthogonal();
  right.normalize();
  Eigen::Matrix3d frame;
  frame << right, f.cross(right), f;
  return frame;
}

}  // namespace omnical

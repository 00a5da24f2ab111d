#include "correction/remap_error.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "model/parallel_rows.h"

namespace omnical {

ObjectSurface ObjectAtDistance(const ObjectSurface& table_surface, double distance_mm) {
  ObjectSurface object = table_surface;
  if (!(distance_mm > 0.0) || !std::isfinite(distance_mm)) {
    object.kind = ObjectSurface::Kind::kInfinity;
    return object;
  }
  if (object.kind == ObjectSurface::Kind::kInfinity) object.kind = ObjectSurface::Kind::kSphere;
  object.distance_mm = distance_mm;
  return object;
}

bool RemapDisplacementPx(const Sensor& sensor, const RemapSettings& settings, const ObjectSurface& object, double col,
                         double row, double* error_px) {
  const ProjectionCache& cache = sensor.cache();
  const Eigen::Vector3d viewpoint(0.0, 0.0, settings.v0_mm);
  const double far_mm = InfinityDistanceMm(sensor);
  Eigen::Vector3d direction, object_point, shown_point;
  if (!settings.screen.Direction(col, row, &direction) || !object.PointAlong(viewpoint, direction, far_mm, &object_point))
    return false;
  Eigen::Vector2d omni_pixel, shown_pixel;
  if (sensor.Project(cache.camera_from_mirror_rotation * object_point + cache.camera_from_mirror_translation,
                     &omni_pixel) != ProjectionStatus::kOk)
    return false;
  Eigen::Vector3d origin_in_camera, ray_in_camera;
  if (sensor.Unproject(omni_pixel, &origin_in_camera, &ray_in_camera) != ProjectionStatus::kOk) return false;
  const Eigen::Vector3d origin = cache.InMirrorFrame(origin_in_camera);
  const Eigen::Vector3d ray = (cache.camera_from_mirror_rotation.transpose() * ray_in_camera).normalized();
  if (!settings.surface.IntersectRay(viewpoint, origin, ray, far_mm, &shown_point)) return false;
  if (!settings.screen.PixelOf(shown_point - viewpoint, &shown_pixel)) return false;
  Eigen::Vector2d offset = shown_pixel - Eigen::Vector2d(col, row);
  // A 360-degree screen wraps: the short way round.
  if (settings.screen.type == VirtualScreen::Type::kPanorama || settings.screen.type == VirtualScreen::Type::kLonLat)
    offset.x() -= settings.screen.width_px * std::round(offset.x() / settings.screen.width_px);
  *error_px = offset.norm();
  return std::isfinite(*error_px);
}

RemapErrorStats RemapErrorAt(const Sensor& sensor, const RemapSettings& settings, const ObjectSurface& object,
                             int stride_px) {
  RemapErrorStats stats;
  stats.object_distance_mm = object.kind == ObjectSurface::Kind::kInfinity ? HUGE_VAL : object.distance_mm;
  const int step = std::max(1, stride_px);
  const int rows = (settings.screen.height_px + step - 1) / step;
  std::vector<long> row_count(rows, 0);
  std::vector<double> row_max(rows, 0.0), row_squares(rows, 0.0);
  ParallelRows(rows, settings.threads, [&](int r) {
    for (int col = step / 2; col < settings.screen.width_px; col += step) {
      double error = 0.0;
      if (!RemapDisplacementPx(sensor, settings, object, col, r * step + step / 2, &error)) continue;
      ++row_count[r];
      row_max[r] = std::max(row_max[r], error);
      row_squares[r] += error * error;
    }
  });
  double sum_squares = 0.0;
  for (int r = 0; r < rows; ++r) {
    stats.samples += row_count[r];
    stats.max_px = std::max(stats.max_px, row_max[r]);
    sum_squares += row_squares[r];
  }
  stats.rms_px = stats.samples > 0 ? std::sqrt(sum_squares / stats.samples) : 0.0;
  return stats;
}

}  // namespace omnical

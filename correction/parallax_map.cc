#include "correction/parallax_map.h"

#include "model/parallel_rows.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace omnical {

ParallaxMap ComputeParallaxMap(const Sensor& sensor, double object_distance_mm, double v0_mm, int threads,
                               const ProgressCallback& progress_callback) {
  ParallaxMap map;
  map.width = sensor.image_width_px();
  map.height = sensor.image_height_px();
  map.error_px.assign(static_cast<size_t>(map.width) * map.height, std::numeric_limits<float>::quiet_NaN());
  const ProjectionCache& cache = sensor.cache();
  const Eigen::Vector3d viewpoint =
      cache.camera_from_mirror_rotation * Eigen::Vector3d(0.0, 0.0, v0_mm) + cache.camera_from_mirror_translation;
  // "Distant" = far enough that the viewpoint spread (mm) is invisible: 1e7 rim radii.
  const double far_mm = 1e7 * sensor.rim_radius_mm();
  ProgressReporter progress(progress_callback, "parallax map", map.height);
  ParallelRows(map.height, threads, [&](int v) {
    if (progress.cancelled()) return;
    Eigen::Matrix2Xd pixels(2, map.width), looked_up;
    Eigen::Matrix3Xd origins, directions, far_points(3, map.width);
    std::vector<ProjectionStatus> ray_status, far_status;
    for (int u = 0; u < map.width; ++u) pixels.col(u) << u, v;
    sensor.UnprojectBatch(pixels, &origins, &directions, &ray_status);
    for (int u = 0; u < map.width; ++u) {
      const Eigen::Vector3d object = origins.col(u) + object_distance_mm * directions.col(u);
      far_points.col(u) = viewpoint + far_mm * (object - viewpoint).normalized();
      if (ray_status[u] != ProjectionStatus::kOk) far_points.col(u).setZero();  // skipped below
    }
    sensor.ProjectBatch(far_points, &looked_up, &far_status);
    for (int u = 0; u < map.width; ++u) {
      if (ray_status[u] != ProjectionStatus::kOk || far_status[u] != ProjectionStatus::kOk) continue;
      map.error_px[static_cast<size_t>(v) * map.width + u] = static_cast<float>((looked_up.col(u) - pixels.col(u)).norm());
    }
    progress.Advance();
  });
  progress.ThrowIfCancelled();
  for (float e : map.error_px)
    if (std::isfinite(e)) map.max_abs_error_px = std::max(map.max_abs_error_px, double(e));
  return map;
}

}  // namespace omnical

#include "correction/remap_job.h"

#include <chrono>
#include <cmath>
#include <random>
#include <string>

#include "model/input_error.h"

namespace omnical {

double ExactnessCheckPx(const Sensor& sensor, const RemapSettings& settings, const RemapTable& table, int samples) {
  std::mt19937 random(1);
  std::uniform_int_distribution<int> col(0, table.width - 1), row(0, table.height - 1);
  double worst = 0.0;
  for (int i = 0; i < samples; ++i) {
    const int u = col(random), v = row(random);
    const size_t k = static_cast<size_t>(v) * table.width + u;
    Eigen::Vector3d point;
    Eigen::Vector2d pixel;
    if (table.map_x[k] < 0.0f || !RemapObjectPoint(sensor, settings, u, v, &point)) continue;
    const ProjectionCache& cache = sensor.cache();
    if (sensor.Project(cache.camera_from_mirror_rotation * point + cache.camera_from_mirror_translation, &pixel) !=
        ProjectionStatus::kOk)
      return HUGE_VAL;  // the table has an entry the scalar path refuses
    worst = std::max(worst, (Eigen::Vector2d(table.map_x[k], table.map_y[k]) - pixel).norm());
  }
  return worst;
}

RemapResult BuildRemap(const Sensor& sensor, const RemapOptions& options) {
  RemapResult result;
  const ResolvedView resolved = ResolveView(sensor, options.view);
  result.settings = resolved.settings;
  result.v0_searched = resolved.v0_searched;
  result.sensor_width_px = sensor.image_width_px();
  result.sensor_height_px = sensor.image_height_px();
  result.rim_radius_mm = sensor.rim_radius_mm();
  const RemapSettings& settings = result.settings;

  const auto start = std::chrono::steady_clock::now();
  result.table = BuildRemapTable(sensor, settings, options.progress);
  result.generation_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const RemapTable& table = result.table;
  result.valid_fraction = double(table.valid_pixels) / (double(table.width) * table.height);
  if (table.valid_pixels == 0)
    throw InputError("view: no output pixel sees the mirror: the view lies outside the mirror's field (elevation " +
                     std::to_string(settings.screen.elevation_bottom_deg) + " .. " +
                     std::to_string(settings.screen.elevation_top_deg) + " deg at most)");
  result.error_at_other_distances = SweepRemapError(
      sensor, settings, SweepOf(SweepDistances::kSummary, settings, result.rim_radius_mm), options.progress);
  result.exactness_px = ExactnessCheckPx(sensor, settings, table, RemapResult::kExactnessSamples);
  return result;
}

}  // namespace omnical

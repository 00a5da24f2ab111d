#include "correction/remap_table.h"

#include "model/grid_table.h"
#include "model/parallel_rows.h"

#include <algorithm>
#include <atomic>
#include <cmath>

namespace omnical {
double InfinityDistanceMm(const Sensor& sensor) { return 1e7 * sensor.rim_radius_mm(); }

bool RemapObjectPoint(const Sensor& sensor, const RemapSettings& settings, double col, double row,
                      Eigen::Vector3d* point_in_mirror) {
  Eigen::Vector3d direction;
  return settings.screen.Direction(col, row, &direction) &&
         settings.surface.PointAlong(Eigen::Vector3d(0.0, 0.0, settings.v0_mm), direction, InfinityDistanceMm(sensor),
                                     point_in_mirror);
}

namespace {

// Exact source pixels (columns) of output points (columns: col, row); NaN where the
// output point has no object point or its projection fails.
Eigen::Matrix2Xd ProjectOutputPoints(const Sensor& sensor, const RemapSettings& settings, const Eigen::Matrix2Xd& output_points) {
  const ProjectionCache& cache = sensor.cache();
  const long count = output_points.cols();
  // Only output points with an object point go to the projector (a dummy point would
  // fall through to its slow scalar path).
  Eigen::Matrix3Xd points(3, count);
  std::vector<long> source(count);
  long with_point = 0;
  for (long i = 0; i < count; ++i) {
    Eigen::Vector3d point;
    if (!RemapObjectPoint(sensor, settings, output_points(0, i), output_points(1, i), &point)) continue;
    points.col(with_point) = cache.camera_from_mirror_rotation * point + cache.camera_from_mirror_translation;
    source[with_point++] = i;
  }
  Eigen::Matrix2Xd pixels = Eigen::Matrix2Xd::Constant(2, count, NAN), projected;
  std::vector<ProjectionStatus> statuses;
  sensor.ProjectBatch(points.leftCols(with_point), &projected, &statuses);
  for (long k = 0; k < with_point; ++k)
    if (statuses[k] == ProjectionStatus::kOk) pixels.col(source[k]) = projected.col(k);
  return pixels;
}

// The image's pixel area (centres at integers, edges at -0.5 and size - 0.5): the image
// border can cut an otherwise imaged field. Made once per table: Sensor's accessors
// visit its variant, too slow per pixel.
struct ImageArea {
  explicit ImageArea(const Sensor& sensor) : max_u(sensor.image_width_px() - 0.5), max_v(sensor.image_height_px() - 0.5) {}
  bool Contains(double x, double y) const { return x >= -0.5 && y >= -0.5 && x <= max_u && y <= max_v; }
  double max_u, max_v;
};

// Projects the output pixels (columns[i], v) exactly into the table; returns how many
// have a source pixel.
long ProjectColumnsOfRow(const Sensor& sensor, const RemapSettings& settings, int v, const std::vector<int>& columns,
                         RemapTable* table) {
  Eigen::Matrix2Xd output_points(2, columns.size());
  for (size_t c = 0; c < columns.size(); ++c) output_points.col(c) = Eigen::Vector2d(columns[c], v);
  const Eigen::Matrix2Xd pixels = ProjectOutputPoints(sensor, settings, output_points);
  long valid = 0;
  for (size_t c = 0; c < columns.size(); ++c) {
    if (std::isnan(pixels(0, c))) continue;
    const size_t i = static_cast<size_t>(v) * table->width + columns[c];
    table->map_x[i] = static_cast<float>(pixels(0, c));
    table->map_y[i] = static_cast<float>(pixels(1, c));
    ++valid;
  }
  return valid;
}

// Output pixels per kNodeSpacingDeg at the screen's centre (the larger of its two
// directions' angles per pixel).
int AutomaticStep(const VirtualScreen& screen) {
  const double cx = 0.5 * (screen.width_px - 1), cy = 0.5 * (screen.height_px - 1);
  double pixel_rad = 0.0;
  for (const Eigen::Vector2d& offset : {Eigen::Vector2d(0.5, 0.0), Eigen::Vector2d(0.0, 0.5)}) {
    Eigen::Vector3d a, b;
    if (screen.Direction(cx - offset.x(), cy - offset.y(), &a) && screen.Direction(cx + offset.x(), cy + offset.y(), &b))
      pixel_rad = std::max(pixel_rad, std::acos(std::clamp(a.dot(b), -1.0, 1.0)));
  }
  return NodeStepPx(pixel_rad);
}

// The interpolated path (model/grid_table.h).
void FillByInterpolation(const Sensor& sensor, const RemapSettings& settings, ProgressReporter& progress,
                         RemapTable* table) {
  GridTableRequest request;
  request.width = table->width;
  request.height = table->height;
  request.step_px = settings.interpolation_step_px > 0 ? settings.interpolation_step_px : AutomaticStep(settings.screen);
  request.threads = settings.threads;
  request.project = [&](const Eigen::Matrix2Xd& output_points) { return ProjectOutputPoints(sensor, settings, output_points); };
  const ImageArea image(sensor);
  request.keep = [&](double x, double y) { return image.Contains(x, y); };
  request.row_done = [&]() { return progress.Advance(); };
  const GridTableFill fill = FillGridTable(request, table->map_x.data(), table->map_y.data());
  table->valid_pixels = fill.valid_pixels;
  table->exact_pixels = fill.exact_pixels;
  table->interpolation_step_px = request.step_px;
  table->worst_cell_check_px = fill.worst_cell_check_px;
}

}  // namespace

RemapTable BuildRemapTable(const Sensor& sensor, const RemapSettings& settings, const ProgressCallback& progress_callback) {
  const VirtualScreen& screen = settings.screen;
  RemapTable table;
  table.width = screen.width_px;
  table.height = screen.height_px;
  table.map_x.assign(static_cast<size_t>(table.width) * table.height, -1.0f);
  table.map_y.assign(table.map_x.size(), -1.0f);
  const ProjectionCache& cache = sensor.cache();
  const Eigen::Matrix3d& rotation = cache.camera_from_mirror_rotation;
  const Eigen::Vector3d& translation = cache.camera_from_mirror_translation;
  const bool cylindrical_screen =
      screen.type == VirtualScreen::Type::kPanorama || screen.type == VirtualScreen::Type::kLonLat;
  table.used_axial_symmetry =
      settings.allow_shortcuts && sensor.is_axial() && cylindrical_screen && settings.surface.IsAxiallySymmetric();
  ProgressReporter progress(progress_callback, "remap table", table.height);
  if (settings.allow_shortcuts && !table.used_axial_symmetry) {
    FillByInterpolation(sensor, settings, progress, &table);
    progress.ThrowIfCancelled();
    return table;
  }
  std::atomic<long> valid{0};
  // Every pixel of row v through the batch projector.
  std::vector<int> all_columns(table.width);
  for (int u = 0; u < table.width; ++u) all_columns[u] = u;
  auto project_row = [&](int v) { valid += ProjectColumnsOfRow(sensor, settings, v, all_columns, &table); };

  if (table.used_axial_symmetry) {
    const ImageArea image(sensor);
    // Column azimuths: phi(col) = phi(0) - col * step; cos/sin once for all rows.
    std::vector<double> cos_phi(table.width), sin_phi(table.width);
    for (int u = 0; u < table.width; ++u) {
      Eigen::Vector3d d;
      screen.Direction(u, 0.0, &d);
      const double phi = std::atan2(d.y(), d.x());
      cos_phi[u] = std::cos(phi), sin_phi[u] = std::sin(phi);
    }
    ParallelRows(table.height, settings.threads, [&](int v) {
      if (progress.cancelled()) return;
      // The row's direction at azimuth 0, turned to 0, 90, 180, 270 deg.
      Eigen::Vector3d d;
      screen.Direction(0.0, v, &d);
      const double horizontal = std::hypot(d.x(), d.y());
      Eigen::Matrix3Xd points(3, 4);
      Eigen::Matrix2Xd pixels;
      std::vector<ProjectionStatus> statuses;
      bool ok = true;
      for (int k = 0; k < 4 && ok; ++k) {
        const double phi = 0.5 * M_PI * k;
        const Eigen::Vector3d turned(horizontal * std::cos(phi), horizontal * std::sin(phi), d.z());
        Eigen::Vector3d point;
        ok = settings.surface.PointAlong(Eigen::Vector3d(0.0, 0.0, settings.v0_mm), turned, InfinityDistanceMm(sensor), &point);
        points.col(k) = rotation * point + translation;
      }
      if (ok) sensor.ProjectBatch(points, &pixels, &statuses);
      if (ok && std::all_of(statuses.begin(), statuses.end(), [](ProjectionStatus s) { return s == ProjectionStatus::kOk; })) {
        const double cu = 0.5 * (pixels(0, 0) + pixels(0, 2)), au = 0.5 * (pixels(0, 0) - pixels(0, 2));
        const double cv = 0.5 * (pixels(1, 1) + pixels(1, 3)), av = 0.5 * (pixels(1, 1) - pixels(1, 3));
        long row_valid = 0;
        for (int u = 0; u < table.width; ++u) {
          const double x = cu + au * cos_phi[u], y = cv + av * sin_phi[u];
          if (!image.Contains(x, y)) continue;
          const size_t i = static_cast<size_t>(v) * table.width + u;
          table.map_x[i] = static_cast<float>(x);
          table.map_y[i] = static_cast<float>(y);
          ++row_valid;
        }
        valid += row_valid;
      } else if (ok && std::any_of(statuses.begin(), statuses.end(),
                                   [](ProjectionStatus s) { return s == ProjectionStatus::kOutsideImage; })) {
        // A circle cut by the image border: other azimuths may be imaged, so this row
        // goes pixel by pixel. (Any other failure holds at every azimuth.)
        project_row(v);
      }
      progress.Advance();
    });
  } else {
    ParallelRows(table.height, settings.threads, [&](int v) {
      if (progress.cancelled()) return;
      project_row(v);
      progress.Advance();
    });
  }
  progress.ThrowIfCancelled();
  table.valid_pixels = valid;
  return table;
}

}  // namespace omnical

#include "correction/remap_table.h"

#include "correction/parallel_rows.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>

namespace omnical {
namespace {

constexpr double kPi = 3.14159265358979323846;

}  // namespace

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

// Weights of the cubic through nodes at -1, 0, 1, 2 (in steps) evaluated at t in [0, 1].
std::array<double, 4> CubicWeights(double t) {
  return {-t * (t - 1.0) * (t - 2.0) / 6.0, (t + 1.0) * (t - 1.0) * (t - 2.0) / 2.0,
          -(t + 1.0) * t * (t - 2.0) / 2.0, (t + 1.0) * t * (t - 1.0) / 6.0};
}

// Output pixels per kNodeSpacingDeg at the screen's centre (the larger of its two
// directions' angles per pixel), at least 2.
int AutomaticStep(const VirtualScreen& screen) {
  const double cx = 0.5 * (screen.width_px - 1), cy = 0.5 * (screen.height_px - 1);
  double pixel_rad = 0.0;
  for (const Eigen::Vector2d& offset : {Eigen::Vector2d(0.5, 0.0), Eigen::Vector2d(0.0, 0.5)}) {
    Eigen::Vector3d a, b;
    if (screen.Direction(cx - offset.x(), cy - offset.y(), &a) && screen.Direction(cx + offset.x(), cy + offset.y(), &b))
      pixel_rad = std::max(pixel_rad, std::acos(std::clamp(a.dot(b), -1.0, 1.0)));
  }
  if (!(pixel_rad > 0.0)) return 2;
  return std::clamp(static_cast<int>(kNodeSpacingDeg * kPi / 180.0 / pixel_rad), 2, 64);
}

// The interpolated path (see remap_table.h). Node (i, j) sits at output point
// ((i - 1) step, (j - 1) step): one node beyond each side, so that the pixel u in cell
// a = u / step has the nodes a .. a + 3 around it.
void FillByInterpolation(const Sensor& sensor, const RemapSettings& settings, ProgressReporter& progress,
                         RemapTable* table) {
  const int step = settings.interpolation_step_px > 0 ? settings.interpolation_step_px : AutomaticStep(settings.screen);
  const int width = table->width, height = table->height;
  const int node_cols = (width - 1) / step + 4, node_rows = (height - 1) / step + 4;
  const int cell_cols = node_cols - 3, cell_rows = node_rows - 3;
  // Each node row, and its cubic along the row at every output column (NaN where a node
  // is missing), so that a pixel needs only the cubic across 4 of these rows.
  std::vector<double> nodes_x(static_cast<size_t>(node_cols) * node_rows), nodes_y(nodes_x.size());
  std::vector<double> along_x(static_cast<size_t>(width) * node_rows), along_y(along_x.size());
  std::vector<std::array<double, 4>> column_weights(width);
  for (int u = 0; u < width; ++u) column_weights[u] = CubicWeights(double(u % step) / step);
  ParallelRows(node_rows, settings.threads, [&](int j) {
    Eigen::Matrix2Xd output_points(2, node_cols);
    for (int i = 0; i < node_cols; ++i) output_points.col(i) = Eigen::Vector2d((i - 1.0) * step, (j - 1.0) * step);
    const Eigen::Matrix2Xd pixels = ProjectOutputPoints(sensor, settings, output_points);
    double* node_x = &nodes_x[static_cast<size_t>(j) * node_cols];
    double* node_y = &nodes_y[static_cast<size_t>(j) * node_cols];
    for (int i = 0; i < node_cols; ++i) node_x[i] = pixels(0, i), node_y[i] = pixels(1, i);
    for (int u = 0; u < width; ++u) {
      const int a = u / step;
      const std::array<double, 4>& w = column_weights[u];
      along_x[static_cast<size_t>(j) * width + u] = w[0] * node_x[a] + w[1] * node_x[a + 1] + w[2] * node_x[a + 2] + w[3] * node_x[a + 3];
      along_y[static_cast<size_t>(j) * width + u] = w[0] * node_y[a] + w[1] * node_y[a + 1] + w[2] * node_y[a + 2] + w[3] * node_y[a + 3];
    }
  });

  // Cells: interpolated only with all 16 nodes and a centre within the check tolerance.
  std::vector<char> interpolated(static_cast<size_t>(cell_cols) * cell_rows, 0);
  std::vector<double> worst_check(cell_rows, 0.0);
  ParallelRows(cell_rows, settings.threads, [&](int b) {
    const std::array<double, 4> w = CubicWeights(0.5);
    Eigen::Matrix2Xd centres(2, cell_cols), guesses(2, cell_cols);
    for (int a = 0; a < cell_cols; ++a) {
      centres.col(a) = Eigen::Vector2d((a + 0.5) * step, (b + 0.5) * step);
      Eigen::Vector2d guess = Eigen::Vector2d::Zero();
      for (int k = 0; k < 4; ++k)
        for (int l = 0; l < 4; ++l) {
          const size_t node = static_cast<size_t>(b + k) * node_cols + a + l;
          guess += w[k] * w[l] * Eigen::Vector2d(nodes_x[node], nodes_y[node]);
        }
      guesses.col(a) = guess;  // NaN if a node is missing
    }
    const Eigen::Matrix2Xd exact = ProjectOutputPoints(sensor, settings, centres);
    for (int a = 0; a < cell_cols; ++a) {
      const double miss = (guesses.col(a) - exact.col(a)).cwiseAbs().maxCoeff();  // NaN fails below
      if (miss < kCellCheckTolerancePx) {
        interpolated[static_cast<size_t>(b) * cell_cols + a] = 1;
        worst_check[b] = std::max(worst_check[b], miss);
      }
    }
  });

  std::atomic<long> valid{0}, exact_pixels{0};
  const ImageArea image(sensor);
  ParallelRows(height, settings.threads, [&](int v) {
    if (progress.cancelled()) return;
    const int b = v / step;
    const std::array<double, 4> w = CubicWeights(double(v % step) / step);
    const size_t row0 = static_cast<size_t>(b) * width;
    const size_t stride = width;
    std::vector<int> exact_columns;
    long row_valid = 0;
    for (int u = 0; u < width; ++u) {
      if (!interpolated[static_cast<size_t>(b) * cell_cols + u / step]) {
        exact_columns.push_back(u);
        continue;
      }
      const size_t k = row0 + u;
      const double x = w[0] * along_x[k] + w[1] * along_x[k + stride] + w[2] * along_x[k + 2 * stride] + w[3] * along_x[k + 3 * stride];
      const double y = w[0] * along_y[k] + w[1] * along_y[k + stride] + w[2] * along_y[k + 2 * stride] + w[3] * along_y[k + 3 * stride];
      if (!image.Contains(x, y)) continue;
      const size_t i = static_cast<size_t>(v) * width + u;
      table->map_x[i] = static_cast<float>(x);
      table->map_y[i] = static_cast<float>(y);
      ++row_valid;
    }
    if (!exact_columns.empty()) {
      const long projected = ProjectColumnsOfRow(sensor, settings, v, exact_columns, table);
      row_valid += projected;
      exact_pixels += projected;
    }
    valid += row_valid;
    progress.Advance();
  });
  table->valid_pixels = valid;
  table->exact_pixels = exact_pixels;
  table->interpolation_step_px = step;
  table->worst_cell_check_px = *std::max_element(worst_check.begin(), worst_check.end());
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
        const double phi = 0.5 * kPi * k;
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

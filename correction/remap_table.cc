#include "correction/remap_table.h"

#include "correction/parallel_rows.h"

#include <algorithm>
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

RemapTable BuildRemapTable(const Sensor& sensor, const RemapSettings& settings, const std::function<void(long)>& progress) {
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
      settings.allow_symmetry && sensor.is_axial() && cylindrical_screen && settings.surface.IsAxiallySymmetric();
  std::atomic<long> valid{0};
  // Every pixel of row v through the batch projector.
  auto project_row = [&](int v) {
    Eigen::Matrix3Xd points(3, table.width);
    std::vector<char> has_point(table.width, 0);
    for (int u = 0; u < table.width; ++u) {
      Eigen::Vector3d point;
      has_point[u] = RemapObjectPoint(sensor, settings, u, v, &point);
      points.col(u) = has_point[u] ? Eigen::Vector3d(rotation * point + translation) : Eigen::Vector3d::Zero();
    }
    Eigen::Matrix2Xd pixels;
    std::vector<ProjectionStatus> statuses;
    sensor.ProjectBatch(points, &pixels, &statuses);
    long row_valid = 0;
    for (int u = 0; u < table.width; ++u) {
      if (!has_point[u] || statuses[u] != ProjectionStatus::kOk) continue;
      const size_t i = static_cast<size_t>(v) * table.width + u;
      table.map_x[i] = static_cast<float>(pixels(0, u));
      table.map_y[i] = static_cast<float>(pixels(1, u));
      ++row_valid;
    }
    valid += row_valid;
  };


  if (table.used_axial_symmetry) {
    // Column azimuths: phi(col) = phi(0) - col * step; cos/sin once for all rows.
    std::vector<double> cos_phi(table.width), sin_phi(table.width);
    for (int u = 0; u < table.width; ++u) {
      Eigen::Vector3d d;
      screen.Direction(u, 0.0, &d);
      const double phi = std::atan2(d.y(), d.x());
      cos_phi[u] = std::cos(phi), sin_phi[u] = std::sin(phi);
    }
    ParallelRows(table.height, settings.threads, [&](int v) {
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
          // The image border can cut an otherwise imaged circle.
          if (x < -0.5 || y < -0.5 || x > sensor.image_width_px() - 0.5 || y > sensor.image_height_px() - 0.5) continue;
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
      if (progress) progress(1);
    });
  } else {
    ParallelRows(table.height, settings.threads, [&](int v) {
      project_row(v);
      if (progress) progress(1);
    });
  }
  table.valid_pixels = valid;
  return table;
}

}  // namespace omnical

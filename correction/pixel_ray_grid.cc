#include "correction/pixel_ray_grid.h"

#include "model/parallel_rows.h"

#include <algorithm>
#include <cmath>

namespace omnical {

PixelRayGrid::PixelRayGrid(const Sensor& sensor, int threads, bool interpolate)
    : sensor_(sensor), width_(sensor.image_width_px()), height_(sensor.image_height_px()), interpolate_(interpolate) {
  if (!interpolate_) return;
  const int columns = width_ + 1, rows = height_ + 1;
  origins_.resize(static_cast<size_t>(columns) * rows);
  directions_.resize(origins_.size());
  valid_.assign(origins_.size(), 0);
  ParallelRows(rows, threads, [&](int j) {
    Eigen::Matrix2Xd pixels(2, columns);
    Eigen::Matrix3Xd origins, directions;
    std::vector<ProjectionStatus> statuses;
    // Corners on the image border lie half a pixel outside the pixel-centre grid, which
    // InImage accepts (the image spans [-0.5, W - 0.5]).
    for (int i = 0; i < columns; ++i) pixels.col(i) << i - 0.5, j - 0.5;
    sensor_.UnprojectBatch(pixels, &origins, &directions, &statuses);
    for (int i = 0; i < columns; ++i) {
      const size_t k = static_cast<size_t>(j) * columns + i;
      valid_[k] = statuses[i] == ProjectionStatus::kOk;
      origins_[k] = origins.col(i);
      directions_[k] = directions.col(i);
    }
  });
}

ProjectionStatus PixelRayGrid::Ray(double u, double v, Eigen::Vector3d* origin, Eigen::Vector3d* direction) const {
  if (!interpolate_) return sensor_.Unproject(Eigen::Vector2d(u, v), origin, direction);
  const double x = u + 0.5, y = v + 0.5;  // in corner-grid units
  const int i = std::clamp(static_cast<int>(std::floor(x)), 0, width_ - 1);
  const int j = std::clamp(static_cast<int>(std::floor(y)), 0, height_ - 1);
  const int columns = width_ + 1;
  const size_t k00 = static_cast<size_t>(j) * columns + i, k10 = k00 + 1, k01 = k00 + columns, k11 = k01 + 1;
  if (!(valid_[k00] && valid_[k10] && valid_[k01] && valid_[k11]))
    return sensor_.Unproject(Eigen::Vector2d(u, v), origin, direction);
  const double a = x - i, b = y - j;
  const double w00 = (1 - a) * (1 - b), w10 = a * (1 - b), w01 = (1 - a) * b, w11 = a * b;
  *origin = w00 * origins_[k00] + w10 * origins_[k10] + w01 * origins_[k01] + w11 * origins_[k11];
  *direction = (w00 * directions_[k00] + w10 * directions_[k10] + w01 * directions_[k01] + w11 * directions_[k11])
                   .normalized();
  return ProjectionStatus::kOk;
}

}  // namespace omnical

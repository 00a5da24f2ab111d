// Rays for sub-pixel samples, fast: exact rays at the pixel corners, bilinear
// interpolation inside a pixel. The rays vary smoothly across a pixel, so the
// interpolation error is second order in the pixel size: tests/render_test.cc bounds it
// at < 0.01 px over the whole image (measured ~1e-4 px). A pixel whose four corners are
// not all on the mirror (the rim, the camera body's reflection) uses exact rays.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "model/sensor.h"

namespace omnical {

class PixelRayGrid {
 public:
  // Unprojects the (W + 1) x (H + 1) pixel corners, rows spread over `threads` threads.
  // With interpolate = false every ray is exact (the slow reference the benchmark and
  // the tests compare with).
  PixelRayGrid(const Sensor& sensor, int threads, bool interpolate = true);

  // The ray of the image point (u, v) (pixel-centre coordinates, as everywhere), camera
  // frame; the unprojection status where it sees no mirror (or the camera body).
  ProjectionStatus Ray(double u, double v, Eigen::Vector3d* origin, Eigen::Vector3d* direction) const;

 private:
  const Sensor& sensor_;
  int width_ = 0, height_ = 0;
  bool interpolate_ = true;
  // Corner (i, j) is the image point (i - 0.5, j - 0.5).
  std::vector<Eigen::Vector3d> origins_, directions_;
  std::vector<char> valid_;
};

}  // namespace omnical

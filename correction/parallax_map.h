// The viewpoint error over the omni image, pixel by pixel, through the exact model (so
// tilted and decentred sensors too): for each pixel, an object D mm along its ray; a
// central virtual projector at V0 sees it in direction d' = unit(T - V0) and looks it up
// at the pixel of a distant object in that direction; the error is the distance between
// that pixel and the true one.
#pragma once

#include <vector>

#include "model/progress.h"
#include "model/sensor.h"

namespace omnical {

struct ParallaxMap {
  int width = 0, height = 0;
  std::vector<float> error_px;  // row-major; NaN where the pixel sees no mirror
  double max_abs_error_px = 0.0;
};

// v0_mm: V0 as z on the mirror axis, mirror frame. Rows are spread over `threads`
// threads; reports stage "parallax map", one step per image row, and throws Cancelled
// when the callback returns false.
ParallaxMap ComputeParallaxMap(const Sensor& sensor, double object_distance_mm, double v0_mm, int threads,
                               const ProgressCallback& progress = nullptr);

}  // namespace omnical

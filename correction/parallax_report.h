// The parallax report: the viewpoint-distribution error of a central virtual projector
// at V0 (seed Sec. 4.2, Eq. 23, Fig. 15) for objects D mm from the mirror, as a curve over
// the field (aligned counterpart) and a map over the omni image (exact sensor), with the
// best V0 when none is given.
#pragma once

#include <optional>
#include <string>

#include "correction/parallax_map.h"
#include "correction/viewpoint_error.h"
#include "model/progress.h"
#include "model/sensor.h"

namespace omnical {

struct ParallaxOptions {
  std::optional<double> distance_mm, n;  // exactly one: object distance from the mirror (mm, or rim radii)
  std::optional<double> v0_mm;           // unset: the V0 minimising the worst pixel error
  int samples = 540;                     // over the mirror radius, for the curve (10..100000)
  int threads = 0;                       // 0: all cores
  ProgressCallback progress;             // stage "parallax map" (image rows)

  // "" or "field: problem".
  std::string Check() const;
};

struct ParallaxResult {
  double distance_mm = 0.0, n = 0.0;
  double v0_mm = 0.0;
  bool v0_searched = false;
  bool axial = true;  // false: the curve is the aligned counterpart's, the map the exact sensor's
  ParallaxCurve curve;
  ParallaxMap map;
};

ParallaxResult ParallaxReport(const Sensor& sensor, const ParallaxOptions& options);

// DIR/parallax.csv (the curve) and DIR/parallax.json (the summary; `sensor_file` as the
// caller names the sensor), atomically; creates DIR.
void WriteParallaxFiles(const std::string& dir, const ParallaxResult& result, const std::string& sensor_file);

}  // namespace omnical

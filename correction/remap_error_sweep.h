// How wrong one remap table is over a range of object distances (seed Eq. 23 in output
// pixels, remap_error.h): the one sweep behind maps.json's error_at_other_distances and
// `parallax --maps`' curve.
//
// Two presets of the one sweep, kept apart because each is a file format people read:
//  - kSummary: n = 1.5, 2, 3, 5, 7, 10, 20, 40, 100 rim radii and infinity, sampled every
//    max(W, H) / 96 output px: ten numbers cheap enough to compute with every table
//    (maps.json, the remap summary line, remap_error.png);
//  - kCurve: n from 1.5 up by factors of 1.25 below 200, the round values 2, 3, 5, 7, 10,
//    20, 40, 100 and the table's own distance (where the error vanishes), then infinity,
//    sampled every max(W, H) / 128 output px: a smooth curve (maps-error.csv/json/png).
// The lists and strides are those the two outputs have always had, so that their numbers
// stay what they were; a user wanting other distances passes them (SweepRemapError below).
#pragma once

#include <vector>

#include "correction/remap_error.h"
#include "model/progress.h"

namespace omnical {

enum class SweepDistances { kSummary, kCurve };

struct RemapErrorSweep {
  std::vector<double> n;  // object distances from V0 in mirror rim radii, ascending; +inf last: infinity
  int stride_px = 1;      // output pixels between samples
};

// The preset's distances and stride for a table with `settings` on a sensor whose rim
// radius is `rim_mm`.
RemapErrorSweep SweepOf(SweepDistances preset, const RemapSettings& settings, double rim_mm);

struct RemapErrorAtDistance {
  double n = 0.0;            // +inf: at infinity
  double distance_mm = 0.0;  // n * rim; +inf: at infinity
  RemapErrorStats stats;
};

// The error at each distance of `sweep` (objects on a surface of the table's kind; a
// sphere for an infinity table). Reports stage "remap error", one step per distance.
std::vector<RemapErrorAtDistance> SweepRemapError(const Sensor& sensor, const RemapSettings& settings,
                                                  const RemapErrorSweep& sweep, const ProgressCallback& progress = nullptr);

}  // namespace omnical

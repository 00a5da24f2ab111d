// The remap job: a view request resolved against a sensor, its table built, checked
// against fresh exact projections, and its error at other object distances measured; what
// `omnical remap` writes (remap_outputs.h) and prints.
#pragma once

#include <vector>

#include "correction/remap_error_sweep.h"
#include "correction/remap_table.h"
#include "correction/view_request.h"
#include "model/progress.h"

namespace omnical {

struct RemapOptions {
  ViewRequest view;
  ProgressCallback progress;  // stages "remap table" (rows), "remap error" (distances)
};

struct RemapResult {
  RemapSettings settings;
  bool v0_searched = false;
  RemapTable table;
  double valid_fraction = 0.0;     // of the output pixels, those that see the mirror
  double generation_seconds = 0.0;  // building the table
  // The largest difference between table entries and fresh scalar projections of their
  // object points over kExactnessSamples random output pixels (+inf if the scalar path
  // refuses an entry): what the files promise.
  static constexpr int kExactnessSamples = 4000;
  double exactness_px = 0.0;
  std::vector<RemapErrorAtDistance> error_at_other_distances;  // SweepDistances::kSummary
  // The sensor's image size and rim radius, for the description on disk.
  int sensor_width_px = 0, sensor_height_px = 0;
  double rim_radius_mm = 0.0;
};

// Throws InputError naming the ViewRequest field ("view: no output pixel sees the mirror
// ..." when the view lies outside the field), Cancelled when the callback says stop.
RemapResult BuildRemap(const Sensor& sensor, const RemapOptions& options);

// The exactness check above over `samples` random output pixels (fixed seed).
double ExactnessCheckPx(const Sensor& sensor, const RemapSettings& settings, const RemapTable& table, int samples);

}  // namespace omnical

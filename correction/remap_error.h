// How wrong a remap table is for objects that are not on its surface (the seed's Eq. 23
// error, in output pixels): an object at distance D' along an output pixel's direction
// from V0 is imaged at omni pixel p'; the table shows p' where the sensor ray of p' meets
// the table's own surface, i.e. at the output point of that intersection's direction from
// V0. The error is the distance from there to the output pixel the ideal central camera
// at V0 uses.
#pragma once

#include <vector>

#include "correction/remap_table.h"

namespace omnical {

struct RemapErrorStats {
  double object_distance_mm = 0.0;  // infinity: +inf
  long samples = 0;                 // output pixels evaluated (imaged both ways)
  double max_px = 0.0, rms_px = 0.0;
};

// The displacement (output px) of the object at `object` (same kind as the table's
// surface, or a sphere for an infinity table) seen along output point (col, row); false
// where either projection fails.
bool RemapDisplacementPx(const Sensor& sensor, const RemapSettings& settings, const ObjectSurface& object, double col,
                         double row, double* error_px);

// Over output pixels on a grid with `stride_px` spacing, rows spread over threads.
RemapErrorStats RemapErrorAt(const Sensor& sensor, const RemapSettings& settings, const ObjectSurface& object,
                             int stride_px);

// The object surface at distance D' of the same kind as the table's (infinity: D' <= 0
// or infinite).
ObjectSurface ObjectAtDistance(const ObjectSurface& table_surface, double distance_mm);

}  // namespace omnical

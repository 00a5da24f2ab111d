// How wrong a remap table on disk (a directory from `remap`) is for objects at other
// distances than it was made for: the kCurve sweep of remap_error_sweep.h, with the
// files `parallax --maps` writes.
#pragma once

#include <string>
#include <vector>

#include "correction/maps_json.h"
#include "correction/remap_error_sweep.h"
#include "model/progress.h"

namespace omnical {

// The sensor stored in maps.json (errors name maps.json's sensor.yaml).
Sensor SensorOfMaps(const MapsDescription& maps);

struct MapsErrorOptions {
  int threads = 0;  // 0: all cores
  ProgressCallback progress;  // stage "remap error" (distances)
};

struct MapsErrorResult {
  MapsDescription maps;
  double rim_radius_mm = 0.0;  // of the sensor evaluated
  std::vector<RemapErrorAtDistance> errors;  // SweepDistances::kCurve: ascending n, infinity last
  // "infinity" or "a sphere at n = 7.000": what the table was made for.
  std::string made_for;
  // The largest error at n (one of the sweep's round values, e.g. 2), output px.
  double MaxPxAtN(double n) const;
};

// `sensor`: the maps' own (SensorOfMaps) or another one with the same image.
MapsErrorResult MapsErrorReport(const MapsDescription& maps, const Sensor& sensor, const MapsErrorOptions& options = {});

// DIR/maps-error.csv and DIR/maps-error.json, atomically; creates DIR.
void WriteMapsErrorFiles(const std::string& dir, const MapsErrorResult& result);

}  // namespace omnical

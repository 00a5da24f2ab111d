// What a caller asks of a virtual screen and its objects, as data (the CLI's view options,
// a Python dict), and its resolution against a sensor: the defaults that depend on the
// sensor's field (size per view, elevation range, Omega_max, the V0 with the least worst
// error at the distance) filled in and everything checked.
//
// Errors are InputError "field: problem", naming the ViewRequest field (e.g. "size: '12'
// is not WxH (e.g. 2048x512)", "distance_mm: the object distance must be > 0"); front ends
// turn the field into their own spelling (the CLI: --size, --distance-mm).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "correction/remap_table.h"
#include "model/optics.h"

namespace omnical {

struct ViewRequest {
  std::string view = "panorama";  // panorama, lonlat, perspective, equiangular
  std::string size;               // "WxH" px; empty: panorama/lonlat 2048x512, perspective 800x600, equiangular 1000x1000
  // panorama, lonlat
  double azimuth0_deg = 180.0;        // azimuth of the left edge: 180 puts azimuth 0 (+x) in the middle
  std::vector<double> elevation_deg;  // {top, bottom}; empty: the sensor's field
  // perspective
  double pan_deg = 0.0, tilt_deg = 0.0, roll_deg = 0.0, hfov_deg = 60.0;
  // equiangular: Omega at the disc's edge; unset: the rim's
  std::optional<double> omega_max_deg;
  // Objects: distance_mm or n (mirror rim radii) from V0, or infinity; exactly one.
  std::optional<double> distance_mm, n;
  bool infinity = false;
  std::string surface = "sphere";    // sphere (around V0), cylinder (about the axis), plane
  std::vector<double> plane_normal;  // plane: x, y, z (mirror frame, from V0 towards it); empty: -z
  std::optional<double> v0_mm;       // unset: the V0 minimising the worst error at the distance
  int threads = 0;                   // 0: all cores
  bool per_pixel = false;            // every output pixel projected (no interpolated grid)

  // The checks that need no sensor: "" or "field: problem".
  std::string Check() const;
};

struct ResolvedView {
  RemapSettings settings;
  bool v0_searched = false;
};

// Check(), then the defaults from the sensor's field (aligned counterpart for a
// misaligned sensor); throws InputError naming the field.
ResolvedView ResolveView(const Sensor& sensor, const ViewRequest& request);

// The distance V0 is chosen for: the surface's, or 1e4 rim radii for infinity (the limit
// of the best V0 for far objects).
double ReferenceDistanceMm(const Sensor& sensor, const ObjectSurface& surface);

// V0 (z on the mirror axis, mm): `given` if set (InputError "v0_mm: not finite"), else
// the one minimising the worst error over `field` at `reference_distance_mm`.
double ResolveV0Mm(const std::vector<FieldSample>& field, double reference_distance_mm, const std::optional<double>& given);

}  // namespace omnical

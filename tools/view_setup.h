// The virtual-screen options `remap` and `unwarp` share, their defaults from the sensor's
// field, and maps.json: the complete description of a remap table on disk (view geometry,
// sensor, object surface, V0), read back by `unwarp --maps` and `parallax --maps`.
#pragma once

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

#include "correction/remap_table.h"
#include "model/optics.h"

namespace omnical::cli {

struct ViewOptions {
  std::string view = "panorama";
  std::string size;  // "WxH"
  double azimuth0_deg = 180.0;  // azimuth 0 (+x) in the middle
  std::vector<double> elevation_deg;  // top, bottom
  double pan_deg = 0.0, tilt_deg = 0.0, roll_deg = 0.0, hfov_deg = 60.0;
  std::optional<double> omega_max_deg;
  std::optional<double> distance_mm, n;
  bool infinity = false;
  std::string surface = "sphere";
  std::vector<double> plane_normal;
  std::optional<double> v0_mm;
  int threads = 0;  // 0: all cores
  bool per_pixel = false;  // no interpolated grid: every pixel projected (the reference)
};

// Registers the options; `required_view` makes --view and a distance mandatory.
void AddViewOptions(CLI::App& sub, ViewOptions* options, bool required_view);
// True if any view option was given on the command line.
bool AnyViewOptionGiven(const CLI::App& sub);

struct ResolvedView {
  RemapSettings settings;
  bool v0_searched = false;
};
// Fills the defaults (size per view, elevation range and Omega_max from the field, the
// V0 that minimises the worst error at the distance) and checks everything; throws
// InputError "option: problem".
ResolvedView ResolveView(const Sensor& sensor, const ViewOptions& options);

// The distance V0 is chosen for: the surface's, or 1e4 rim radii for infinity (the limit
// of the best V0 for far objects; V0 only matters there for finite distances).
double ReferenceDistanceMm(const Sensor& sensor, const ObjectSurface& surface);
// V0 (z on the mirror axis, mm): `given` if set (InputError on --v0 if not finite), else
// the one minimising the worst error over `field` at `reference_distance_mm`.
double ResolveV0Mm(const std::vector<FieldSample>& field, double reference_distance_mm, const std::optional<double>& given);

// maps.json pieces. The view entry holds the geometry completely, with the formula from
// output pixel to viewing direction.
nlohmann::json ScreenJson(const VirtualScreen& screen);
nlohmann::json SurfaceJson(const ObjectSurface& surface, double rim_mm);

struct MapsDescription {
  std::string dir, sensor_yaml;
  RemapSettings settings;
  nlohmann::json json;
};
// Reads DIR/maps.json (and checks it against DIR/maps.yml.gz when `table` is given):
// throws InputError naming the file and field.
MapsDescription ReadMapsDescription(const std::string& dir, RemapTable* table);

}  // namespace omnical::cli

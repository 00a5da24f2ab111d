#include "tools/view_setup.h"
#include "tools/cli_common.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "correction/map_export.h"
#include "correction/viewpoint_error.h"
#include "model/input_error.h"
#include "model/optics.h"

namespace omnical::cli {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;
const char* const kViewOptionNames[] = {"--view",      "--size",     "--azimuth0-deg", "--elevation-deg", "--pan-deg",
                                        "--tilt-deg",  "--roll-deg", "--hfov-deg",     "--omega-max-deg", "--distance-mm",
                                        "--n",         "--infinity", "--surface",      "--plane-normal",  "--v0",
                                        "--per-pixel"};

std::string OptionError(const std::string& option, const std::string& problem) { return option + ": " + problem; }

}  // namespace

void AddViewOptions(CLI::App& sub, ViewOptions* options, bool required_view) {
  auto* view = sub.add_option("--view", options->view, "Virtual screen: panorama, lonlat, perspective, equiangular")
                   ->check(CLI::IsMember({"panorama", "lonlat", "perspective", "equiangular"}));
  if (required_view) view->required();
  sub.add_option("--size", options->size,
                 "Output size WxH px (default: panorama/lonlat 2048x512, perspective 800x600, equiangular 1000x1000)");
  sub.add_option("--azimuth0-deg", options->azimuth0_deg, "panorama/lonlat: azimuth of the left edge (deg)")->capture_default_str();
  sub.add_option("--elevation-deg", options->elevation_deg,
                 "panorama/lonlat: elevation of the top and bottom edges, 'top,bottom' (deg; default: the field)")
      ->delimiter(',')->expected(2);
  sub.add_option("--pan-deg", options->pan_deg, "perspective: azimuth of the optical axis (deg)");
  sub.add_option("--tilt-deg", options->tilt_deg, "perspective: elevation of the optical axis (deg)");
  sub.add_option("--roll-deg", options->roll_deg, "perspective: roll about the optical axis (deg)");
  sub.add_option("--hfov-deg", options->hfov_deg, "perspective: horizontal field of view (deg)");
  sub.add_option("--omega-max-deg", options->omega_max_deg, "equiangular: Omega at the disc's edge (deg; default: the rim's)");
  auto* distance = sub.add_option("--distance-mm", options->distance_mm, "Objects at this distance D from V0 (mm)");
  auto* n = sub.add_option("--n", options->n, "Objects at n mirror rim radii from V0");
  auto* infinity = sub.add_flag("--infinity", options->infinity, "Objects at infinity (the central approximation)");
  distance->excludes(n)->excludes(infinity);
  n->excludes(infinity);
  sub.add_option("--surface", options->surface,
                 "Object surface at the distance: sphere (around V0), cylinder (about the axis), plane")
      ->check(CLI::IsMember({"sphere", "cylinder", "plane"}));
  sub.add_option("--plane-normal", options->plane_normal, "plane: its normal 'x,y,z' in the mirror frame, from V0 towards it")
      ->delimiter(',')->expected(3);
  sub.add_option("--v0", options->v0_mm, "Viewpoint V0, z on the mirror axis (mm, mirror frame); "
                                         "default: the one minimising the worst error at the distance");
  sub.add_option("--threads", options->threads, "Threads (0: all cores)")->check(kNonNegative);
  sub.add_flag("--per-pixel", options->per_pixel,
               "Project every output pixel (no interpolated grid; its error bound is 0.01 px)");
  if (required_view) {
    sub.callback([distance, n, infinity]() {
      if (distance->count() + n->count() + infinity->count() == 0)
        throw CLI::RequiredError("--distance-mm, --n or --infinity");
    });
  }
}

bool AnyViewOptionGiven(const CLI::App& sub) {
  for (const char* name : kViewOptionNames)
    if (sub.count(name) > 0) return true;
  return false;
}

ResolvedView ResolveView(const Sensor& sensor, const ViewOptions& options) {
  ResolvedView resolved;
  RemapSettings& settings = resolved.settings;
  VirtualScreen& screen = settings.screen;
  const auto type = ParseScreenType(options.view);
  if (!type) throw InputError(OptionError("--view", "unknown view '" + options.view + "'"));
  screen.type = *type;
  const double rim = sensor.rim_radius_mm();

  if (options.size.empty()) {
    const bool wide = screen.type == VirtualScreen::Type::kPanorama || screen.type == VirtualScreen::Type::kLonLat;
    screen.width_px = wide ? 2048 : screen.type == VirtualScreen::Type::kPerspective ? 800 : 1000;
    screen.height_px = wide ? 512 : screen.type == VirtualScreen::Type::kPerspective ? 600 : 1000;
  } else {
    char x = 0;
    std::istringstream in(options.size);
    if (!(in >> screen.width_px >> x >> screen.height_px) || (x != 'x' && x != 'X') || !in.eof())
      throw InputError(OptionError("--size", "'" + options.size + "' is not WxH (e.g. 2048x512)"));
  }

  // Objects.
  ObjectSurface& surface = settings.surface;
  if (options.infinity) {
    surface.kind = ObjectSurface::Kind::kInfinity;
  } else {
    if (!options.distance_mm && !options.n)
      throw InputError(OptionError("--distance-mm", "give the object distance (--distance-mm D or --n N) or --infinity"));
    const auto kind = ParseSurfaceKind(options.surface);
    if (!kind || *kind == ObjectSurface::Kind::kInfinity) throw InputError(OptionError("--surface", "unknown '" + options.surface + "'"));
    surface.kind = *kind;
    surface.distance_mm = options.distance_mm ? *options.distance_mm : options.n ? *options.n * rim : NAN;
    if (!std::isfinite(surface.distance_mm) || surface.distance_mm <= 0.0)
      throw InputError(OptionError(options.n ? "--n" : "--distance-mm", "the object distance must be > 0"));
  }
  if (!options.plane_normal.empty()) {
    if (surface.kind != ObjectSurface::Kind::kPlane) throw InputError(OptionError("--plane-normal", "only with --surface plane"));
    surface.plane_normal = Eigen::Vector3d(options.plane_normal[0], options.plane_normal[1], options.plane_normal[2]);
    if (!(surface.plane_normal.allFinite() && surface.plane_normal.norm() > 0.0))
      throw InputError(OptionError("--plane-normal", "zero or not finite"));
    surface.plane_normal.normalize();
  }
  if (const std::string problem = surface.Check(); !problem.empty()) throw InputError("--" + problem);

  // The field (aligned counterpart for a misaligned sensor): the default ranges and V0.
  const double reference_distance = ReferenceDistanceMm(sensor, surface);
  const std::vector<FieldSample> field = AnalyzeField(sensor, 360, reference_distance);
  double omega_min = HUGE_VAL, omega_max = 0.0;
  for (const FieldSample& f : field) omega_min = std::min(omega_min, f.ray.omega_rad), omega_max = std::max(omega_max, f.ray.omega_rad);
  omega_min /= kDeg, omega_max /= kDeg;
  settings.v0_mm = ResolveV0Mm(field, reference_distance, options.v0_mm);
  resolved.v0_searched = !options.v0_mm;

  screen.azimuth0_deg = options.azimuth0_deg;
  if (options.elevation_deg.size() == 2) {
    screen.elevation_top_deg = options.elevation_deg[0];
    screen.elevation_bottom_deg = options.elevation_deg[1];
  } else {
    screen.elevation_top_deg = std::min(89.0, omega_max - 90.0);
    screen.elevation_bottom_deg = std::max(-60.0, omega_min - 90.0);
  }
  screen.pan_deg = options.pan_deg, screen.tilt_deg = options.tilt_deg, screen.roll_deg = options.roll_deg;
  screen.hfov_deg = options.hfov_deg;
  screen.omega_max_deg = options.omega_max_deg ? *options.omega_max_deg : omega_max;
  if (const std::string problem = screen.Check(); !problem.empty()) throw InputError("--" + problem);
  settings.allow_shortcuts = !options.per_pixel;
  settings.threads = options.threads > 0 ? options.threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  return resolved;
}

double ReferenceDistanceMm(const Sensor& sensor, const ObjectSurface& surface) {
  return surface.kind == ObjectSurface::Kind::kInfinity ? 1e4 * sensor.rim_radius_mm() : surface.distance_mm;
}

double ResolveV0Mm(const std::vector<FieldSample>& field, double reference_distance_mm, const std::optional<double>& given) {
  if (!given) return BestViewpointMm(field, reference_distance_mm);
  if (!std::isfinite(*given)) throw InputError(OptionError("--v0", "not finite"));
  return *given;
}

nlohmann::json ScreenJson(const VirtualScreen& s) {
  nlohmann::json j;
  j["type"] = ScreenTypeName(s.type);
  j["size_px"] = {s.width_px, s.height_px};
  j["frame"] = "mirror frame: z along the mirror axis from the lens to the mirror; "
               "d(Omega, phi) = (sin Omega cos phi, sin Omega sin phi, -cos Omega), elevation = Omega - 90 deg";
  j["pixel_convention"] = "col, row; the centre of pixel (0, 0) is at (0, 0)";
  switch (s.type) {
    case VirtualScreen::Type::kPanorama:
    case VirtualScreen::Type::kLonLat:
      j["azimuth0_deg"] = s.azimuth0_deg;
      j["elevation_top_deg"] = s.elevation_top_deg;
      j["elevation_bottom_deg"] = s.elevation_bottom_deg;
      j["column_direction"] = "phi = azimuth0_deg - 360 (col + 0.5) / width";
      j["row_direction"] =
          s.type == VirtualScreen::Type::kPanorama
              ? "tan(elevation) = tan(top) + (tan(bottom) - tan(top)) (row + 0.5) / height"
              : "elevation = top + (bottom - top) (row + 0.5) / height";
      break;
    case VirtualScreen::Type::kPerspective: {
      j["pan_deg"] = s.pan_deg, j["tilt_deg"] = s.tilt_deg, j["roll_deg"] = s.roll_deg, j["hfov_deg"] = s.hfov_deg;
      j["focal_px"] = s.FocalPx();
      j["principal_point_px"] = {0.5 * (s.width_px - 1), 0.5 * (s.height_px - 1)};
      const Eigen::Matrix3d r = s.MirrorFromView();
      j["mirror_from_view"] = {{r(0, 0), r(0, 1), r(0, 2)}, {r(1, 0), r(1, 1), r(1, 2)}, {r(2, 0), r(2, 1), r(2, 2)}};
      j["direction"] = "d = mirror_from_view * ((col - cx) / f, (row - cy) / f, 1), normalised";
      break;
    }
    case VirtualScreen::Type::kEquiangular:
      j["omega_max_deg"] = s.omega_max_deg;
      j["direction"] = "r = |(col - cx, row - cy)|, Omega = omega_max_deg r / (width / 2), phi = atan2(row - cy, col - cx), "
                       "(cx, cy) = ((width - 1) / 2, (height - 1) / 2)";
      break;
  }
  return j;
}

nlohmann::json SurfaceJson(const ObjectSurface& surface, double rim_mm) {
  nlohmann::json j;
  j["kind"] = SurfaceKindName(surface.kind);
  if (surface.kind != ObjectSurface::Kind::kInfinity) {
    j["distance_mm"] = surface.distance_mm;
    j["n"] = surface.distance_mm / rim_mm;
  }
  if (surface.kind == ObjectSurface::Kind::kPlane)
    j["plane_normal"] = {surface.plane_normal.x(), surface.plane_normal.y(), surface.plane_normal.z()};
  return j;
}

MapsDescription ReadMapsDescription(const std::string& dir, RemapTable* table) {
  MapsDescription description;
  description.dir = dir;
  const std::string path = (std::filesystem::path(dir) / "maps.json").string();
  std::ifstream in(path);
  if (!in) throw InputError(InputMessage(path, "", "cannot be read (not a directory written by omnical remap?)"));
  nlohmann::json& j = description.json;
  try {
    in >> j;
  } catch (const nlohmann::json::exception&) {
    throw InputError(InputMessage(path, "", "is not valid JSON"));
  }
  std::string field;
  try {
    RemapSettings& settings = description.settings;
    VirtualScreen& s = settings.screen;
    field = "view.type";
    const auto type = ParseScreenType(j.at("view").at("type").get<std::string>());
    if (!type) throw InputError(InputMessage(path, field, "unknown view"));
    s.type = *type;
    field = "view.size_px";
    s.width_px = j["view"].at("size_px").at(0).get<int>();
    s.height_px = j["view"]["size_px"].at(1).get<int>();
    const nlohmann::json& v = j["view"];
    switch (s.type) {
      case VirtualScreen::Type::kPanorama:
      case VirtualScreen::Type::kLonLat:
        field = "view.azimuth0_deg/elevation_top_deg/elevation_bottom_deg";
        s.azimuth0_deg = v.at("azimuth0_deg").get<double>();
        s.elevation_top_deg = v.at("elevation_top_deg").get<double>();
        s.elevation_bottom_deg = v.at("elevation_bottom_deg").get<double>();
        break;
      case VirtualScreen::Type::kPerspective:
        field = "view.pan_deg/tilt_deg/roll_deg/hfov_deg";
        s.pan_deg = v.at("pan_deg").get<double>(), s.tilt_deg = v.at("tilt_deg").get<double>();
        s.roll_deg = v.at("roll_deg").get<double>(), s.hfov_deg = v.at("hfov_deg").get<double>();
        break;
      case VirtualScreen::Type::kEquiangular:
        field = "view.omega_max_deg";
        s.omega_max_deg = v.at("omega_max_deg").get<double>();
        break;
    }
    if (const std::string problem = s.Check(); !problem.empty()) throw InputError(InputMessage(path, "view", problem));
    field = "surface.kind";
    const auto kind = ParseSurfaceKind(j.at("surface").at("kind").get<std::string>());
    if (!kind) throw InputError(InputMessage(path, field, "unknown surface"));
    settings.surface.kind = *kind;
    if (*kind != ObjectSurface::Kind::kInfinity) {
      field = "surface.distance_mm";
      settings.surface.distance_mm = j["surface"].at("distance_mm").get<double>();
    }
    if (*kind == ObjectSurface::Kind::kPlane) {
      field = "surface.plane_normal";
      const auto& normal = j["surface"].at("plane_normal");
      settings.surface.plane_normal = Eigen::Vector3d(normal.at(0).get<double>(), normal.at(1).get<double>(), normal.at(2).get<double>());
    }
    if (const std::string problem = settings.surface.Check(); !problem.empty())
      throw InputError(InputMessage(path, "surface", problem));
    field = "v0_mm";
    settings.v0_mm = j.at("v0_mm").get<double>();
    field = "sensor.yaml";
    description.sensor_yaml = j.at("sensor").at("yaml").get<std::string>();
  } catch (const nlohmann::json::exception&) {
    throw InputError(InputMessage(path, field, "missing or of the wrong type"));
  }
  if (table != nullptr) {
    const std::string maps = (std::filesystem::path(dir) / "maps.yml.gz").string();
    *table = ReadOpenCvMaps(maps);
    if (table->width != description.settings.screen.width_px || table->height != description.settings.screen.height_px)
      throw InputError(InputMessage(maps, "map_x", "is " + std::to_string(table->width) + " x " + std::to_string(table->height) +
                                                      " px but maps.json says " + std::to_string(description.settings.screen.width_px) +
                                                      " x " + std::to_string(description.settings.screen.height_px) +
                                                      ": inconsistent map files"));
  }
  return description;
}

}  // namespace omnical::cli

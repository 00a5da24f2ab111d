#include "correction/maps_json.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "correction/map_export.h"
#include "model/io/atomic_write.h"
#include "model/input_error.h"
#include "model/object_distance.h"

namespace omnical {
namespace {

// The view entry: the geometry completely, with the formula from output pixel to direction.
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

nlohmann::json FilesJson(const MapFiles& files) {
  nlohmann::json j = nlohmann::json::object();
  if (files.opencv) j["opencv"] = {{"float", "maps.yml.gz"}, {"fixed_point", "maps_fixed.yml.gz"}};
  if (files.ffmpeg) j["ffmpeg"] = {{"xmap", "xmap.pgm"}, {"ymap", "ymap.pgm"}, {"command", files.ffmpeg_command}};
  if (files.npy) j["npy"] = {{"map_x", "map_x.npy"}, {"map_y", "map_y.npy"}};
  return j;
}

nlohmann::json FiniteOr(double value, const char* otherwise) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(otherwise);
}

}  // namespace

void WriteMapsJson(const std::string& dir, const RemapResult& result, const MapFiles& files, const SensorSource& sensor) {
  const RemapSettings& settings = result.settings;
  const RemapTable& table = result.table;
  nlohmann::json residual = nlohmann::json::array();
  for (const RemapErrorAtDistance& e : result.error_at_other_distances)
    residual.push_back({{"n", FiniteOr(e.n, "infinity")},
                        {"distance_mm", FiniteOr(e.distance_mm, "infinity")},
                        {"max_px", e.stats.max_px},
                        {"rms_px", e.stats.rms_px},
                        {"samples", e.stats.samples}});
  nlohmann::json j;
  j["view"] = ScreenJson(settings.screen);
  j["sensor"] = {{"file", sensor.file}, {"yaml", sensor.yaml}, {"image_size_px", {result.sensor_width_px, result.sensor_height_px}}};
  j["surface"] = SurfaceJson(settings.surface, result.rim_radius_mm);
  j["v0_mm"] = settings.v0_mm;
  j["v0_searched"] = result.v0_searched;
  j["map_convention"] = "omni-image pixel to sample (centre of pixel (0, 0) at (0, 0)); -1 where the output pixel sees no mirror";
  j["files"] = FilesJson(files);
  j["valid_fraction"] = result.valid_fraction;
  j["used_axial_symmetry"] = table.used_axial_symmetry;
  j["method"] = table.used_axial_symmetry ? "axial symmetry" : table.interpolation_step_px > 0 ? "interpolated grid" : "per pixel";
  if (table.interpolation_step_px > 0)
    j["interpolation"] = {{"step_px", table.interpolation_step_px},
                          {"pixels_projected_one_by_one", table.exact_pixels},
                          {"worst_cell_check_px", table.worst_cell_check_px},
                          {"bound_px", 0.01}};
  j["generation_seconds"] = result.generation_seconds;
  j["threads"] = settings.threads;
  j["exactness_check"] = {{"max_error_px", result.exactness_px},
                          {"meaning", "table entries vs fresh exact projections of their object points, " +
                                          std::to_string(RemapResult::kExactnessSamples) + " random pixels"}};
  j["error_at_other_distances"] = residual;
  WriteFileAtomically((std::filesystem::path(dir) / "maps.json").string(),
                      [&](std::ostream& out) { out << j.dump(2) << '\n'; });
}

MapsDescription ReadMapsDescription(const std::string& dir, RemapTable* table) {
  MapsDescription description;
  description.dir = dir;
  description.path = (std::filesystem::path(dir) / "maps.json").string();
  const std::string& path = description.path;
  std::ifstream in(path);
  if (!in) throw InputError(InputMessage(path, "", "cannot be read (not a directory written by omnical remap?)"));
  nlohmann::json j;
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
    description.surface_json = j["surface"].dump();
    field = "v0_mm";
    settings.v0_mm = j.at("v0_mm").get<double>();
    if (const std::string problem = ViewpointProblem(settings.v0_mm); !problem.empty())
      throw InputError(InputMessage(path, "v0_mm", problem));
    field = "sensor.yaml";
    description.sensor_yaml = j.at("sensor").at("yaml").get<std::string>();
  } catch (const nlohmann::json::exception&) {
    throw InputError(InputMessage(path, field, "missing or of the wrong type"));
  }
  try {  // optional: only unwarp needs it, and says so when it is missing
    description.sensor_width_px = j.at("sensor").at("image_size_px").at(0).get<int>();
    description.sensor_height_px = j.at("sensor").at("image_size_px").at(1).get<int>();
  } catch (const nlohmann::json::exception&) {
    description.sensor_width_px = description.sensor_height_px = 0;
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

}  // namespace omnical

#include "calib/synthetic/scene.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <random>
#include <set>

#include "model/input_error.h"
#include "model/io/yaml_field_reader.h"
#include "model/io/sensor_yaml.h"
#include "model/object_distance.h"

namespace omnical {
namespace {

// A random seed: a whole number an unsigned 32-bit generator takes (a negative or huge
// one cast to unsigned is undefined behaviour; found by the scene fuzzer with "seed: -1").
unsigned SeedOr(const YamlFieldReader& reader, const YAML::Node& map, const std::string& where, unsigned fallback) {
  const double seed = reader.NumberOr(map, "seed", where, fallback);
  if (!(seed >= 0.0 && seed <= 4294967295.0) || seed != std::floor(seed))
    reader.Fail(YamlFieldReader::Join(where, "seed"), "must be a whole number from 0 to 4294967295");
  return static_cast<unsigned>(seed);
}

// A view's name is the stem of the files written for it in the output directory: letters,
// digits, '-', '_' and '.', not starting with '.' (a name "../x" wrote outside it).
void CheckFileStem(const YamlFieldReader& reader, const std::string& name, const std::string& field) {
  const bool plain = std::all_of(name.begin(), name.end(), [](unsigned char c) {
    return std::isalnum(c) || c == '-' || c == '_' || c == '.';
  });
  if (name.empty() || name.size() > 100 || name[0] == '.' || !plain)
    reader.Fail(field, "'" + name + "': must be 1-100 letters, digits, '-', '_' or '.' (not first): it names the view's files");
}

constexpr double kRad = M_PI / 180.0;

using SceneReader = YamlFieldReader;

struct Placement {
  double omega_deg, azimuth_deg, distance_mm, roll_deg, tilt_x_deg, tilt_y_deg;
};

Placement ReadPlacement(const SceneReader& reader, const YAML::Node& node, const std::string& where, double rim_mm) {
  reader.RejectUnknown(node, where, {"omega_deg", "azimuth_deg", "distance_mm", "distance_n", "roll_deg", "tilt_deg"});
  Placement p{};
  p.omega_deg = reader.Number(node["omega_deg"], where + ".omega_deg");
  p.azimuth_deg = reader.NumberOr(node, "azimuth_deg", where, 0.0);
  if (node["distance_mm"] && node["distance_n"]) reader.Fail(where, "give distance_mm or distance_n, not both");
  p.distance_mm = node["distance_n"] ? rim_mm * reader.Number(node["distance_n"], where + ".distance_n")
                                     : reader.Number(node["distance_mm"], where + ".distance_mm");
  if (const std::string why = ObjectDistanceProblem(p.distance_mm); !why.empty()) reader.Fail(where + ".distance_mm", why);
  p.roll_deg = reader.NumberOr(node, "roll_deg", where, 0.0);
  // Two angles (about the board's x and y axes), not a range.
  if (const YAML::Node tilt = node["tilt_deg"]) {
    if (!tilt.IsSequence() || tilt.size() != 2) reader.Fail(where + ".tilt_deg", "must be [about x, about y] in degrees");
    p.tilt_x_deg = reader.Number(tilt[0], where + ".tilt_deg[0]");
    p.tilt_y_deg = reader.Number(tilt[1], where + ".tilt_deg[1]");
  }
  return p;
}

}  // namespace

void PlaceTarget(const Sensor& sensor, const CalibrationTarget& target, double omega_deg, double azimuth_deg,
                 double distance_mm, double roll_deg, double tilt_x_deg, double tilt_y_deg,
                 Eigen::Matrix3d* camera_from_target_rotation, Eigen::Vector3d* camera_from_target_translation_mm) {
  const double omega = omega_deg * kRad, azimuth = azimuth_deg * kRad;
  const Eigen::Vector3d outward(std::sin(omega) * std::cos(azimuth), std::sin(omega) * std::sin(azimuth), -std::cos(omega));
  const Eigen::Vector3d centre = distance_mm * outward;  // mirror frame, from the vertex
  // Printed face towards the vertex; board x horizontal (perpendicular to the mirror axis).
  const Eigen::Vector3d normal = -outward;
  Eigen::Vector3d x_axis = Eigen::Vector3d::UnitZ().cross(normal);
  if (x_axis.norm() < 1e-9) x_axis = Eigen::Vector3d::UnitX();
  x_axis.normalize();
  const Eigen::Vector3d y_axis = normal.cross(x_axis);
  Eigen::Matrix3d facing;
  facing << x_axis, y_axis, normal;
  const Eigen::Matrix3d mirror_from_target =
      facing * Eigen::AngleAxisd(roll_deg * kRad, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
      Eigen::AngleAxisd(tilt_x_deg * kRad, Eigen::Vector3d::UnitX()).toRotationMatrix() *
      Eigen::AngleAxisd(tilt_y_deg * kRad, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const ProjectionCache& cache = sensor.cache();
  const Eigen::Vector2d board_centre = target.centre_mm();
  *camera_from_target_rotation = cache.camera_from_mirror_rotation * mirror_from_target;
  *camera_from_target_translation_mm =
      cache.camera_from_mirror_rotation * (centre - mirror_from_target * Eigen::Vector3d(board_centre.x(), board_centre.y(), 0.0)) +
      cache.camera_from_mirror_translation;
}

Scene LoadSceneYaml(const std::string& path) {
  const SceneReader reader(path);
  const YAML::Node root = reader.LoadFile();
  Scene scene;
  scene.path = path;
  try {
    reader.RejectUnknown(root, "", {"sensor", "render", "environment", "targets", "views", "random_views"});
    // Sensor: a file, or the sensor's sections inline.
    const YAML::Node sensor = root["sensor"];
    if (!sensor) reader.Fail("sensor", "missing (a sensor file, or camera/mirror/pose inline)");
    if (sensor.IsScalar()) {
      scene.sensor = LoadSensorYaml(reader.Resolve(sensor.as<std::string>()));
    } else {
      YAML::Emitter text;
      text << sensor;
      scene.sensor = ParseSensorYaml(text.c_str(), path);
    }
    const double rim = scene.sensor->rim_radius_mm();

    if (const YAML::Node render = root["render"]) {
      reader.RejectUnknown(render, "render",
                           {"samples_per_pixel", "noise_sigma", "blur_sigma_px", "vignetting", "seed", "jpeg_quality", "colour"});
      ImageFormation& f = scene.formation;
      const double spp = reader.NumberOr(render, "samples_per_pixel", "render", 16);
      const int side = static_cast<int>(std::lround(std::sqrt(spp)));
      if (side < 1 || side > 16 || side * side != spp)
        reader.Fail("render.samples_per_pixel", "must be a perfect square from 1 to 256");
      f.samples_per_pixel = static_cast<int>(spp);
      f.noise_sigma = reader.NumberOr(render, "noise_sigma", "render", 0.0);
      f.blur_sigma_px = reader.NumberOr(render, "blur_sigma_px", "render", 0.0);
      f.vignetting = reader.NumberOr(render, "vignetting", "render", 0.0);
      f.seed = SeedOr(reader, render, "render", 1);
      if (f.noise_sigma < 0.0 || f.noise_sigma > 100.0) reader.Fail("render.noise_sigma", "must be in [0, 100] grey levels");
      if (f.blur_sigma_px < 0.0 || f.blur_sigma_px > 50.0) reader.Fail("render.blur_sigma_px", "must be in [0, 50] px");
      if (f.vignetting < 0.0 || f.vignetting > 1.0) reader.Fail("render.vignetting", "must be in [0, 1]");
      const double quality = reader.NumberOr(render, "jpeg_quality", "render", 0);
      if (!(quality >= 0 && quality <= 100) || quality != std::floor(quality))
        reader.Fail("render.jpeg_quality", "must be 0 (PNG) or a JPEG quality 1 to 100");
      f.jpeg_quality = static_cast<int>(quality);
      if (render["colour"]) {
        const std::string colour = reader.Text(render["colour"], "render.colour");
        if (colour != "true" && colour != "false") reader.Fail("render.colour", "must be true or false");
        f.colour = colour == "true";
      }
    }
    if (const YAML::Node env = root["environment"]) {
      reader.RejectUnknown(env, "environment", {"type", "level", "half_size_mm", "tile_mm", "levels", "tiles"});
      Environment& e = scene.environment;
      const std::string type = env["type"] ? env["type"].as<std::string>() : "room";
      if (type == "grey") {
        e.type = Environment::Type::kGrey;
      } else if (type != "room") {
        reader.Fail("environment.type", "unknown environment '" + type + "' (room or grey)");
      }
      e.level = reader.NumberOr(env, "level", "environment", e.level);
      e.half_size_mm = reader.NumberOr(env, "half_size_mm", "environment", e.half_size_mm);
      e.tile_mm = reader.NumberOr(env, "tile_mm", "environment", e.tile_mm);
      const auto levels = reader.Range(env, "levels", "environment", {e.low, e.high});
      e.low = levels.first, e.high = levels.second;
      if (env["tiles"]) {
        const std::string tiles = reader.Text(env["tiles"], "environment.tiles");
        if (tiles != "all" && tiles != "floor_ceiling")
          reader.Fail("environment.tiles", "must be all or floor_ceiling, not '" + tiles + "'");
        e.tiled_walls = tiles == "all";
      }
      if (!(e.half_size_mm > 0.0) || !(e.tile_mm > 0.0)) reader.Fail("environment", "half_size_mm and tile_mm must be > 0");
    }

    // Targets by name.
    const YAML::Node targets = root["targets"];
    if (!targets || !targets.IsMap() || targets.size() == 0)
      reader.Fail("targets", "missing (a map of name: target spec file)");
    std::map<std::string, std::pair<std::string, std::shared_ptr<const CalibrationTarget>>> by_name;
    std::map<std::string, BoardWarp> warps;  // a bent board: {spec: file, warp_mm: [x, y]}
    for (const auto& entry : targets) {
      const std::string name = entry.first.as<std::string>();
      const std::string where = "targets." + name;
      std::string spec_text;
      if (entry.second.IsMap()) {
        reader.RejectUnknown(entry.second, where, {"spec", "warp_mm"});
        if (!entry.second["spec"]) reader.Fail(where + ".spec", "missing (the target spec file)");
        spec_text = reader.Text(entry.second["spec"], where + ".spec");
        if (const YAML::Node warp = entry.second["warp_mm"]) {
          if (!warp.IsSequence() || warp.size() != 2)
            reader.Fail(where + ".warp_mm", "must be [along x, along y]: the deflection at the centre in mm");
          warps[name] = {reader.Number(warp[0], where + ".warp_mm[0]"), reader.Number(warp[1], where + ".warp_mm[1]")};
          if (!(std::abs(warps[name].x_mm) <= 100.0 && std::abs(warps[name].y_mm) <= 100.0))
            reader.Fail(where + ".warp_mm", "must be within +-100 mm");
        }
      } else {
        spec_text = reader.Text(entry.second, where);
      }
      const std::string spec = reader.Resolve(spec_text);
      try {
        by_name[name] = {spec, std::make_shared<const CalibrationTarget>(CalibrationTarget::FromYaml(spec))};
      } catch (const InputError& error) {
        reader.Fail(where, std::string("cannot load the target spec: ") + error.what());
      }
    }
    auto place = [&](const std::string& name, const Placement& p, const std::string& where, bool strict,
                     PlacedTarget* placed) {
      const auto& [spec, target] = by_name.at(name);
      placed->name = name;
      placed->spec_path = spec;
      placed->target = target;
      placed->surface = WarpedSurface::Of(*target, warps.count(name) ? warps.at(name) : BoardWarp());
      PlaceTarget(*scene.sensor, *target, p.omega_deg, p.azimuth_deg, p.distance_mm, p.roll_deg, p.tilt_x_deg,
                  p.tilt_y_deg, &placed->camera_from_target_rotation, &placed->camera_from_target_translation_mm);
      const Eigen::Vector2d c = target->centre_mm();
      const Eigen::Vector3d centre =
          placed->camera_from_target_rotation * Eigen::Vector3d(c.x(), c.y(), 0.0) + placed->camera_from_target_translation_mm;
      Eigen::Vector2d pixel;
      const ProjectionStatus status = scene.sensor->Project(centre, &pixel);
      if (status != ProjectionStatus::kOk) {
        if (strict)
          reader.Fail(where, std::string("the target centre is not seen in the mirror (") + StatusName(status) +
                                 "): behind the mirror or beyond its field?");
        return false;
      }
      return true;
    };

    if (const YAML::Node views = root["views"]) {
      if (!views.IsSequence()) reader.Fail("views", "must be a list");
      for (size_t i = 0; i < views.size(); ++i) {
        const std::string where = "views[" + std::to_string(i) + "]";
        SceneView view;
        view.name = views[i]["name"] ? views[i]["name"].as<std::string>() : "view" + std::to_string(i);
        CheckFileStem(reader, view.name, where + ".name");
        for (const auto& entry : views[i]) {
          const std::string key = entry.first.as<std::string>();
          if (key == "name") continue;
          if (!by_name.count(key)) reader.Fail(where + "." + key, "no target of that name in targets");
          PlacedTarget placed;
          place(key, ReadPlacement(reader, entry.second, where + "." + key, rim), where + "." + key, true, &placed);
          view.targets.push_back(placed);
        }
        if (view.targets.empty()) reader.Fail(where, "places no target");
        scene.views.push_back(view);
      }
    }
    if (const YAML::Node random = root["random_views"]) {
      const std::string where = "random_views";
      reader.RejectUnknown(random, where, {"count", "target", "omega_deg", "azimuth_deg", "distance_mm", "distance_n",
                                           "tilt_deg", "roll_deg", "seed", "prefix"});
      const double count = reader.Number(random["count"], where + ".count");
      if (count < 1 || count > 10000 || count != std::floor(count)) reader.Fail(where + ".count", "must be 1 to 10000");
      if (!random["target"]) reader.Fail(where + ".target", "missing");
      const std::string name = random["target"].as<std::string>();
      if (!by_name.count(name)) reader.Fail(where + ".target", "no target named '" + name + "'");
      const auto omega = reader.Range(random, "omega_deg", where, {30.0, 120.0});
      const auto azimuth = reader.Range(random, "azimuth_deg", where, {0.0, 360.0});
      if (random["distance_mm"] && random["distance_n"]) reader.Fail(where, "give distance_mm or distance_n, not both");
      auto distance = random["distance_n"] ? reader.Range(random, "distance_n", where, {5.0, 10.0})
                                           : reader.Range(random, "distance_mm", where, {5.0 * rim, 10.0 * rim});
      if (random["distance_n"]) distance = {distance.first * rim, distance.second * rim};
      for (double end : {distance.first, distance.second})
        if (const std::string why = ObjectDistanceProblem(end); !why.empty()) reader.Fail(where + ".distance", why);
      const auto tilt = reader.Range(random, "tilt_deg", where, {0.0, 30.0});
      const auto roll = reader.Range(random, "roll_deg", where, {-30.0, 30.0});
      const std::string prefix = random["prefix"] ? random["prefix"].as<std::string>() : "random";
      if (random["prefix"]) CheckFileStem(reader, prefix, where + ".prefix");
      std::mt19937 rng(SeedOr(reader, random, where, 1));
      auto uniform = [&](std::pair<double, double> r) { return std::uniform_real_distribution<double>(r.first, r.second)(rng); };
      for (int k = 0; k < static_cast<int>(count); ++k) {
        SceneView view;
        char id[64];
        std::snprintf(id, sizeof id, "%s%03d", prefix.c_str(), k);
        view.name = id;
        PlacedTarget placed;
        bool found = false;
        for (int attempt = 0; attempt < 200 && !found; ++attempt) {
          const double magnitude = uniform(tilt), tilt_axis = uniform({0.0, 2.0 * M_PI});
          const Placement p{uniform(omega), uniform(azimuth), uniform(distance), uniform(roll),
                            magnitude * std::cos(tilt_axis), magnitude * std::sin(tilt_axis)};
          found = place(name, p, where, false, &placed);
        }
        if (!found) reader.Fail(where, "no visible placement found within the ranges (Omega beyond the mirror's field?)");
        view.targets.push_back(placed);
        scene.views.push_back(view);
      }
    }
    if (scene.views.empty()) reader.Fail("views", "the scene has no views (views or random_views)");
    // Each view's image and ground truth are written as <name>.png / .json beside scene.json.
    std::set<std::string> names;
    for (const SceneView& view : scene.views) {
      if (view.name == "scene") reader.Fail("views", "a view named 'scene' would overwrite scene.json");
      if (!names.insert(view.name).second) reader.Fail("views", "two views are named '" + view.name + "'");
    }
  } catch (const YAML::Exception& error) {
    reader.Fail("", std::string("unexpected YAML structure: ") + error.what());
  }
  return scene;
}

}  // namespace omnical

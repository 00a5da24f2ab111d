#include "correction/maps_error_report.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <thread>

#include "model/io/atomic_write.h"
#include "model/io/sensor_yaml.h"

namespace omnical {

Sensor SensorOfMaps(const MapsDescription& maps) { return ParseSensorYaml(maps.sensor_yaml, maps.path + ": sensor.yaml"); }

double MapsErrorResult::MaxPxAtN(double n) const {
  for (const RemapErrorAtDistance& e : errors)
    if (e.n == n) return e.stats.max_px;
  return NAN;
}

MapsErrorResult MapsErrorReport(const MapsDescription& maps, const Sensor& sensor, const MapsErrorOptions& options) {
  MapsErrorResult result;
  result.maps = maps;
  RemapSettings settings = maps.settings;
  settings.threads = options.threads > 0 ? options.threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const double rim = result.rim_radius_mm = sensor.rim_radius_mm();
  result.errors = SweepRemapError(sensor, settings, SweepOf(SweepDistances::kCurve, settings, rim), options.progress);
  const ObjectSurface& surface = settings.surface;
  result.made_for = surface.kind == ObjectSurface::Kind::kInfinity
                        ? std::string("infinity")
                        : "a " + std::string(SurfaceKindName(surface.kind)) + " at n = " +
                              std::to_string(surface.distance_mm / rim).substr(0, 5);
  return result;
}

void WriteMapsErrorFiles(const std::string& dir, const MapsErrorResult& result) {
  CreateOutputDirectory(dir);
  const std::filesystem::path out(dir);
  WriteFileAtomically((out / "maps-error.csv").string(), [&](std::ostream& stream) {
    stream << "n,distance_mm,max_px,rms_px,samples\n" << std::setprecision(10);
    for (const RemapErrorAtDistance& e : result.errors) {
      if (std::isfinite(e.n)) stream << e.n << ',' << e.distance_mm;
      else stream << "inf,inf";
      stream << ',' << e.stats.max_px << ',' << e.stats.rms_px << ',' << e.stats.samples << '\n';
    }
  });
  nlohmann::json j;
  j["maps"] = result.maps.dir;
  j["made_for"] = nlohmann::json::parse(result.maps.surface_json);
  j["v0_mm"] = result.maps.settings.v0_mm;
  for (const RemapErrorAtDistance& e : result.errors)
    j["error"].push_back({{"n", std::isfinite(e.n) ? nlohmann::json(e.n) : nlohmann::json("infinity")},
                          {"max_px", e.stats.max_px},
                          {"rms_px", e.stats.rms_px}});
  WriteFileAtomically((out / "maps-error.json").string(), [&](std::ostream& stream) { stream << j.dump(2) << '\n'; });
}

}  // namespace omnical

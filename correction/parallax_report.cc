#include "correction/parallax_report.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <thread>

#include "model/io/atomic_write.h"
#include "model/input_error.h"
#include "model/object_distance.h"
#include "model/optics.h"

namespace omnical {

std::string ParallaxOptions::Check() const {
  if (distance_mm && n) return "n: give only one of distance_mm and n";
  if (!distance_mm && !n) return "distance_mm: give the object distance (distance_mm or n)";
  const double distance = distance_mm ? *distance_mm : *n;
  if (!(std::isfinite(distance) && distance > 0.0)) return std::string(n ? "n" : "distance_mm") + ": must be > 0";
  if (v0_mm)
    if (const std::string why = ViewpointProblem(*v0_mm); !why.empty()) return "v0_mm: " + why;
  if (samples < 10 || samples > 100000) return "samples: " + std::to_string(samples) + " (10..100000)";
  if (threads < 0) return "threads: must be >= 0";
  return "";
}

ParallaxResult ParallaxReport(const Sensor& sensor, const ParallaxOptions& options) {
  if (const std::string why = options.Check(); !why.empty()) throw InputError(why);
  ParallaxResult result;
  const double rim = sensor.rim_radius_mm();
  result.distance_mm = options.distance_mm ? *options.distance_mm : *options.n * rim;
  if (const std::string why = ObjectDistanceProblem(result.distance_mm); !why.empty())
    throw InputError(std::string(options.n ? "n" : "distance_mm") + ": " + why);
  result.n = result.distance_mm / rim;
  result.axial = sensor.is_axial();
  const std::vector<FieldSample> field = AnalyzeField(sensor, options.samples, result.distance_mm);
  result.v0_searched = !options.v0_mm;
  result.v0_mm = options.v0_mm ? *options.v0_mm : BestViewpointMm(field, result.distance_mm);
  result.curve = ComputeParallaxCurve(field, result.distance_mm, result.v0_mm);
  const int threads = options.threads > 0 ? options.threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  result.map = ComputeParallaxMap(sensor, result.distance_mm, result.v0_mm, threads, options.progress);
  return result;
}

void WriteParallaxFiles(const std::string& dir, const ParallaxResult& result, const std::string& sensor_file) {
  CreateOutputDirectory(dir);
  const std::filesystem::path out(dir);
  const ParallaxCurve& curve = result.curve;
  WriteFileAtomically((out / "parallax.csv").string(), [&](std::ostream& stream) {
    stream << "omega_deg,x_mm,error_deg,error_px\n" << std::setprecision(10);
    for (size_t i = 0; i < curve.omega_deg.size(); ++i)
      stream << curve.omega_deg[i] << ',' << curve.x_mm[i] << ',' << curve.error_deg[i] << ',' << curve.error_px[i] << '\n';
  });
  nlohmann::json j;
  j["sensor"] = sensor_file;
  j["object_distance_mm"] = result.distance_mm;
  j["n"] = result.n;
  j["v0_mm"] = result.v0_mm;
  j["v0_searched"] = result.v0_searched;
  j["max_abs_error_px"] = curve.max_abs_error_px;
  j["max_abs_error_deg"] = curve.max_abs_error_deg;
  j["map_max_abs_error_px"] = result.map.max_abs_error_px;
  j["analysed_as"] = result.axial ? "axial" : "curve: aligned counterpart; map: exact sensor";
  WriteFileAtomically((out / "parallax.json").string(), [&](std::ostream& stream) { stream << j.dump(2) << '\n'; });
}

}  // namespace omnical

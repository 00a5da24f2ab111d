// omnical parallax: the viewpoint-distribution error of a central virtual projector
// (seed Sec. 4.2, Eq. 23, Fig. 15) for objects at n mirror radii or D mm from the
// mirror, as JSON, CSV, a curve and an error map over the omni image.
#include <nlohmann/json.hpp>

#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <optional>
#include <ostream>
#include <thread>

#include "correction/parallax_map.h"
#include "correction/remap_error.h"
#include "correction/viewpoint_error.h"
#include "model/atomic_write.h"
#include "model/input_error.h"
#include "tools/commands.h"
#include "calib/report/plot.h"
#include "tools/progress.h"
#include "tools/view_setup.h"

namespace omnical::cli {
namespace {

struct Options {
  std::string sensor_path, out_dir, maps_dir;
  std::optional<double> n, distance_mm, v0_mm;
  int samples = 540;
};

// --maps: how wrong a remap table made for one distance is at others, in output pixels.
void RunForMaps(const Options& options, const Context& context) {
  MapsDescription maps = ReadMapsDescription(options.maps_dir, nullptr);
  const std::string maps_json = options.maps_dir + "/maps.json";
  const Sensor sensor = options.sensor_path.empty() ? ParseSensorYaml(maps.sensor_yaml, maps_json + ": sensor.yaml")
                                                    : LoadSensorYaml(options.sensor_path);
  RemapSettings& settings = maps.settings;
  settings.threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const double rim = sensor.rim_radius_mm();
  std::vector<double> ns;
  for (double n = 1.5; n < 200.0; n *= 1.25) ns.push_back(n);
  for (double n : {2.0, 3.0, 5.0, 7.0, 10.0, 20.0, 40.0, 100.0}) ns.push_back(n);
  if (settings.surface.kind != ObjectSurface::Kind::kInfinity) ns.push_back(settings.surface.distance_mm / rim);
  std::sort(ns.begin(), ns.end());
  ns.erase(std::unique(ns.begin(), ns.end()), ns.end());
  const int stride = std::max(1, std::max(settings.screen.width_px, settings.screen.height_px) / 128);
  std::vector<RemapErrorStats> stats;
  {
    Progress progress("map error", static_cast<long>(ns.size()) + 1, context.quiet);
    for (double n : ns) stats.push_back(RemapErrorAt(sensor, settings, ObjectAtDistance(settings.surface, n * rim), stride)), progress.Advance();
    stats.push_back(RemapErrorAt(sensor, settings, ObjectAtDistance(settings.surface, HUGE_VAL), stride));
    progress.Advance();
  }
  CreateOutputDirectory(options.out_dir);
  const std::filesystem::path dir(options.out_dir);
  WriteOutput((dir / "maps-error.csv").string(), [&](std::ostream& out) {
    out << "n,distance_mm,max_px,rms_px,samples\n" << std::setprecision(10);
    for (size_t i = 0; i < ns.size(); ++i)
      out << ns[i] << ',' << ns[i] * rim << ',' << stats[i].max_px << ',' << stats[i].rms_px << ',' << stats[i].samples << '\n';
    out << "inf,inf," << stats.back().max_px << ',' << stats.back().rms_px << ',' << stats.back().samples << '\n';
  });
  std::vector<double> log_n, max_px, rms_px;
  for (size_t i = 0; i < ns.size(); ++i) log_n.push_back(std::log10(ns[i])), max_px.push_back(stats[i].max_px), rms_px.push_back(stats[i].rms_px);
  char title[200];
  const std::string made_for = settings.surface.kind == ObjectSurface::Kind::kInfinity
                                   ? std::string("infinity")
                                   : "a " + std::string(SurfaceKindName(settings.surface.kind)) + " at n = " +
                                         std::to_string(settings.surface.distance_mm / rim).substr(0, 5);
  std::snprintf(title, sizeof title, "%s %dx%d made for objects %s%s: error elsewhere", ScreenTypeName(settings.screen.type),
                settings.screen.width_px, settings.screen.height_px,
                settings.surface.kind == ObjectSurface::Kind::kInfinity ? "at " : "on ", made_for.c_str());
  PlotPanel panel{title, "log10 n (object distance from V0 in mirror rim radii)", "error (output px)"};
  panel.series.push_back({"max", log_n, max_px, SeriesColor(0)});
  panel.series.push_back({"rms", log_n, rms_px, SeriesColor(1)});
  panel.series.push_back({"at infinity (max)", {log_n.front(), log_n.back()}, {stats.back().max_px, stats.back().max_px}, SeriesColor(2)});
  panel.series.back().dashed = true;
  WritePng((dir / "maps-error.png").string(), RenderPanel(panel, 900, 560));
  nlohmann::json result;
  result["maps"] = options.maps_dir;
  result["made_for"] = maps.json["surface"];
  result["v0_mm"] = settings.v0_mm;
  for (size_t i = 0; i < stats.size(); ++i)
    result["error"].push_back({{"n", i < ns.size() ? nlohmann::json(ns[i]) : nlohmann::json("infinity")},
                               {"max_px", stats[i].max_px}, {"rms_px", stats[i].rms_px}});
  WriteOutput((dir / "maps-error.json").string(), [&](std::ostream& out) { out << result.dump(2) << '\n'; });
  if (!context.quiet) {
    const size_t at_n2 = std::find(ns.begin(), ns.end(), 2.0) - ns.begin();  // in the list by construction
    std::printf("%s: made for %s; at infinity max %.3f px, at n = 2 max %.3f px (output px) -> %s\n", options.maps_dir.c_str(),
                made_for.c_str(), stats.back().max_px, stats[at_n2].max_px, options.out_dir.c_str());
  }
}

void Run(const Options& options, const Context& context) {
  if (!options.maps_dir.empty()) return RunForMaps(options, context);
  if (options.sensor_path.empty()) throw InputError("parallax: --sensor is required (or --maps DIR)");
  const Sensor sensor = LoadSensorYaml(options.sensor_path);
  const double rim = sensor.rim_radius_mm();
  const double distance = options.distance_mm ? *options.distance_mm : *options.n * rim;
  CreateOutputDirectory(options.out_dir);
  const std::filesystem::path dir(options.out_dir);

  const std::vector<FieldSample> field = AnalyzeField(sensor, options.samples, distance);
  const double v0 = options.v0_mm ? *options.v0_mm : BestViewpointMm(field, distance);
  const ParallaxCurve curve = ComputeParallaxCurve(field, distance, v0);

  ParallaxMap map;
  {
    Progress progress("parallax map", sensor.image_height_px(), context.quiet);
    map = ComputeParallaxMap(sensor, distance, v0, std::max(1u, std::thread::hardware_concurrency()),
                             [&](long rows) { progress.Advance(rows); });
  }

  WriteOutput((dir / "parallax.csv").string(), [&](std::ostream& out) {
    out << "omega_deg,x_mm,error_deg,error_px\n" << std::setprecision(10);
    for (size_t i = 0; i < curve.omega_deg.size(); ++i)
      out << curve.omega_deg[i] << ',' << curve.x_mm[i] << ',' << curve.error_deg[i] << ',' << curve.error_px[i] << '\n';
  });

  char title[160];
  std::snprintf(title, sizeof title, "Viewpoint error, object at n = %.3g mirror radii (%.0f mm), V0 = %.3f mm",
                distance / rim, distance, v0);
  PlotPanel panel{title, "Omega (deg)", "error (px in the omni image)"};
  panel.series.push_back({"epsilon x dh/dOmega", curve.omega_deg, curve.error_px, SeriesColor(0)});
  WritePng((dir / "parallax.png").string(), RenderPanel(panel, 900, 560));

  cv::Mat values(map.height, map.width, CV_32F, map.error_px.data());
  std::snprintf(title, sizeof title, "|error| of a central projector at V0, object at n = %.3g", distance / rim);
  WritePng((dir / "error_map.png").string(), RenderFalseColourMap(values, title, "px"));

  nlohmann::json result;
  result["sensor"] = options.sensor_path;
  result["object_distance_mm"] = distance;
  result["n"] = distance / rim;
  result["v0_mm"] = v0;
  result["v0_searched"] = !options.v0_mm.has_value();
  result["max_abs_error_px"] = curve.max_abs_error_px;
  result["max_abs_error_deg"] = curve.max_abs_error_deg;
  result["map_max_abs_error_px"] = map.max_abs_error_px;
  result["analysed_as"] = sensor.is_axial() ? "axial" : "curve: aligned counterpart; map: exact sensor";
  WriteOutput((dir / "parallax.json").string(), [&](std::ostream& out) { out << result.dump(2) << '\n'; });
  if (!context.quiet)
    std::printf("%s: object at n = %.3g (%.0f mm), V0 = %.3f mm: max |error| %.3f px (%.3f deg); map max %.3f px -> %s\n",
                options.sensor_path.c_str(), distance / rim, distance, v0, curve.max_abs_error_px,
                curve.max_abs_error_deg, map.max_abs_error_px, options.out_dir.c_str());
}

}  // namespace

Command ParallaxCommand() {
  return {"parallax", "Viewpoint-distribution error (seed Eq. 23) for near objects: curve, error map, best V0",
          [](CLI::App& sub, const Context& context) -> CommandAction {
            auto options = std::make_shared<Options>();
            sub.add_option("--sensor", options->sensor_path, "Sensor file (YAML); with --maps, instead of the maps' own");
            auto* maps = sub.add_option("--maps", options->maps_dir,
                                        "A directory from `omnical remap`: the table's error at other object distances (output px)");
            sub.add_option("--out", options->out_dir, "Output directory")->required();
            auto* n = sub.add_option("--n", options->n, "Object distance from the mirror, in mirror rim radii")
                          ->check(kPositive);
            auto* d = sub.add_option("--distance-mm", options->distance_mm, "Object distance from the mirror, mm")
                          ->check(kPositive);
            n->excludes(d);
            sub.add_option("--v0", options->v0_mm, "Viewpoint V0, z on the mirror axis (mm, mirror frame); "
                                                   "default: the one minimising the worst pixel error");
            sub.add_option("--samples", options->samples, "Samples over the mirror radius")
                ->check(CLI::Range(10, 100000))->capture_default_str();
            sub.callback([n, d, maps]() {
              if (maps->count() == 0 && n->count() == 0 && d->count() == 0) throw CLI::RequiredError("--n or --distance-mm");
            });
            return [options, &context]() { Run(*options, context); };
          }};
}

}  // namespace omnical::cli

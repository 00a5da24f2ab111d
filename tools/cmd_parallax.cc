// omnical parallax: the viewpoint-distribution error of a central virtual projector
// (seed Sec. 4.2, Eq. 23, Fig. 15) for objects at n mirror radii or D mm from the
// mirror, as JSON, CSV, a curve and an error map over the omni image.
#include <nlohmann/json.hpp>

#include <opencv2/core.hpp>

#include <filesystem>
#include <iomanip>
#include <optional>
#include <ostream>
#include <thread>

#include "correction/parallax_map.h"
#include "correction/viewpoint_error.h"
#include "model/input_error.h"
#include "tools/commands.h"
#include "tools/plot.h"
#include "tools/progress.h"

namespace omnical::cli {
namespace {

struct Options {
  std::string sensor_path, out_dir;
  std::optional<double> n, distance_mm, v0_mm;
  int samples = 540;
};

void Run(const Options& options, const Context& context) {
  const Sensor sensor = LoadSensorYaml(options.sensor_path);
  const double rim = sensor.rim_radius_mm();
  const double distance = options.distance_mm ? *options.distance_mm : *options.n * rim;
  std::filesystem::create_directories(options.out_dir);
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
            sub.add_option("--sensor", options->sensor_path, "Sensor file (YAML)")->required();
            sub.add_option("--out", options->out_dir, "Output directory")->required();
            auto* n = sub.add_option("--n", options->n, "Object distance from the mirror, in mirror rim radii")
                          ->check(CLI::PositiveNumber);
            auto* d = sub.add_option("--distance-mm", options->distance_mm, "Object distance from the mirror, mm")
                          ->check(CLI::PositiveNumber);
            n->excludes(d);
            sub.add_option("--v0", options->v0_mm, "Viewpoint V0, z on the mirror axis (mm, mirror frame); "
                                                   "default: the one minimising the worst pixel error");
            sub.add_option("--samples", options->samples, "Samples over the mirror radius")
                ->check(CLI::Range(10, 100000))->capture_default_str();
            sub.callback([n, d]() {
              if (n->count() == 0 && d->count() == 0) throw CLI::RequiredError("--n or --distance-mm");
            });
            return [options, &context]() { Run(*options, context); };
          }};
}

}  // namespace omnical::cli

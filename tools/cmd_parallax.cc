// omnical parallax: the viewpoint-distribution error of a central virtual projector
// (seed Sec. 4.2, Eq. 23, Fig. 15) for objects at n mirror radii or D mm from the
// mirror, as JSON, CSV, a curve and an error map over the omni image
// (correction/parallax_report.h); with --maps, a remap table's error at other object
// distances (correction/maps_error_report.h).
#include <cstdio>

#include "calib/report/correction_figures.h"
#include "correction/maps_error_report.h"
#include "correction/parallax_report.h"
#include "model/input_error.h"
#include "tools/commands.h"
#include "tools/field_flags.h"
#include "tools/progress.h"
#include "model/io/sensor_yaml.h"

namespace omnical::cli {
namespace {

struct ParallaxFlags {
  std::string sensor_path, out_dir, maps_dir;
  ParallaxOptions job;
};

void RunForMaps(const ParallaxFlags& options, const Context& context) {
  const MapsDescription maps = ReadMapsDescription(options.maps_dir);
  const Sensor sensor = options.sensor_path.empty() ? SensorOfMaps(maps) : LoadSensorYaml(options.sensor_path);
  MapsErrorOptions job;
  job.progress = TerminalProgress(context);
  const MapsErrorResult result = MapsErrorReport(maps, sensor, job);
  WriteMapsErrorFiles(options.out_dir, result);
  WriteMapsErrorFigures(options.out_dir, result);
  if (!context.quiet)
    std::printf("%s: made for %s; at infinity max %.3f px, at n = 2 max %.3f px (output px) -> %s\n", options.maps_dir.c_str(),
                result.made_for.c_str(), result.errors.back().stats.max_px, result.MaxPxAtN(2.0), options.out_dir.c_str());
}

void RunParallax(ParallaxFlags& options, const Context& context) {
  if (!options.maps_dir.empty()) return RunForMaps(options, context);
  if (options.sensor_path.empty()) throw InputError("parallax: --sensor is required (or --maps DIR)");
  const Sensor sensor = LoadSensorYaml(options.sensor_path);
  options.job.progress = TerminalProgress(context);
  const FlagTable flags = FlagsOf({"distance_mm", "n", "samples"}, {{"v0_mm", "--v0"}});
  const ParallaxResult result = NamingFlags(flags, [&] { return ParallaxReport(sensor, options.job); });
  WriteParallaxFiles(options.out_dir, result, options.sensor_path);
  WriteParallaxFigures(options.out_dir, result);
  if (!context.quiet)
    std::printf("%s: object at n = %.3g (%.0f mm), V0 = %.3f mm: max |error| %.3f px (%.3f deg); map max %.3f px -> %s\n",
                options.sensor_path.c_str(), result.n, result.distance_mm, result.v0_mm, result.curve.max_abs_error_px,
                result.curve.max_abs_error_deg, result.map.max_abs_error_px, options.out_dir.c_str());
}

}  // namespace

Command ParallaxCommand() {
  return {"parallax", "Viewpoint-distribution error (seed Eq. 23) for near objects: curve, error map, best V0",
          [](CLI::App& sub, const Context& context) -> CommandAction {
            auto options = std::make_shared<ParallaxFlags>();
            ParallaxOptions& job = options->job;
            sub.add_option("--sensor", options->sensor_path, "Sensor file (YAML); with --maps, instead of the maps' own");
            auto* maps = sub.add_option("--maps", options->maps_dir,
                                        "A directory from `omnical remap`: the table's error at other object distances (output px)");
            sub.add_option("--out", options->out_dir, "Output directory")->required();
            auto* n = sub.add_option("--n", job.n, "Object distance from the mirror, in mirror rim radii")->check(kPositive);
            auto* d = sub.add_option("--distance-mm", job.distance_mm, "Object distance from the mirror, mm")->check(kPositive);
            n->excludes(d);
            sub.add_option("--v0", job.v0_mm, "Viewpoint V0, z on the mirror axis (mm, mirror frame); "
                                              "default: the one minimising the worst pixel error");
            sub.add_option("--samples", job.samples, "Samples over the mirror radius")
                ->check(CLI::Range(10, 100000))->capture_default_str();
            sub.callback([n, d, maps]() {
              if (maps->count() == 0 && n->count() == 0 && d->count() == 0) throw CLI::RequiredError("--n or --distance-mm");
            });
            return [options, &context]() { RunParallax(*options, context); };
          }};
}

}  // namespace omnical::cli

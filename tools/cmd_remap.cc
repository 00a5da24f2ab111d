// omnical remap: a remap table from the omni image to a virtual screen, exact for objects
// on the chosen surface (or at infinity), exported for OpenCV, ffmpeg and NumPy, with
// maps.json describing the view completely and how wrong the table is at other distances
// (correction/remap_job.h, remap_outputs.h).
#include <nlohmann/json.hpp>

#include <cstdio>
#include <fstream>
#include <sstream>

#include "calib/report/correction_figures.h"
#include "correction/remap_outputs.h"
#include "tools/commands.h"
#include "tools/progress.h"
#include "tools/view_options.h"
#include "model/io/sensor_yaml.h"

namespace omnical::cli {
namespace {

struct RemapFlags {
  std::string sensor_path, out_dir;
  std::vector<std::string> formats{"opencv"};
  RemapOptions job;
};

void PrintSummary(const RemapResult& result, const MapFiles& files, const std::string& out_dir) {
  const RemapSettings& settings = result.settings;
  const RemapTable& table = result.table;
  char objects[96] = "at infinity";
  if (settings.surface.kind != ObjectSurface::Kind::kInfinity)
    std::snprintf(objects, sizeof objects, "on a %s at %.1f mm (n = %.3g)", SurfaceKindName(settings.surface.kind),
                  settings.surface.distance_mm, settings.surface.distance_mm / result.rim_radius_mm);
  std::printf("%s %dx%d, objects %s, V0 = %.3f mm: %.1f%% of pixels see the mirror, %.3f s%s -> %s\n",
              ScreenTypeName(settings.screen.type), table.width, table.height, objects, settings.v0_mm,
              100.0 * result.valid_fraction, result.generation_seconds,
              table.used_axial_symmetry ? " (axial symmetry)" : table.interpolation_step_px > 0 ? " (interpolated grid)" : "",
              out_dir.c_str());
  std::printf("  exact to %.2g px; error at other distances (max output px):", result.exactness_px);
  for (const RemapErrorAtDistance& e : result.error_at_other_distances)
    std::printf(" n=%s %.3g", (std::isfinite(e.n) ? nlohmann::json(e.n) : nlohmann::json("infinity")).dump().c_str(),
                e.stats.max_px);
  std::printf("\n");
  if (files.ffmpeg) std::printf("  ffmpeg: %s\n", files.ffmpeg_command.c_str());
}

void RunRemap(RemapFlags& options, const Context& context) {
  const Sensor sensor = LoadSensorYaml(options.sensor_path);
  options.job.progress = TerminalProgress(context);
  const RemapResult result = NamingFlags(ViewFlags(), [&] { return BuildRemap(sensor, options.job); });
  std::vector<MapFormat> formats;
  for (const std::string& name : options.formats) formats.push_back(*ParseMapFormat(name));
  std::stringstream sensor_yaml;
  sensor_yaml << std::ifstream(options.sensor_path).rdbuf();
  const MapFiles files = WriteRemapOutputs(options.out_dir, result, formats, {options.sensor_path, sensor_yaml.str()});
  WriteRemapFigures(options.out_dir, result);
  if (!context.quiet) PrintSummary(result, files, options.out_dir);
}

}  // namespace

Command RemapCommand() {
  return {"remap", "Remap tables to a virtual screen (panorama, lonlat, perspective, equiangular), exact at a known distance",
          [](CLI::App& sub, const Context& context) -> CommandAction {
            auto options = std::make_shared<RemapFlags>();
            sub.add_option("--sensor", options->sensor_path, "Sensor file (YAML)")->required();
            sub.add_option("--out", options->out_dir, "Output directory")->required();
            sub.add_option("--format", options->formats, "Formats: opencv, ffmpeg, npy (comma separated)")
                ->delimiter(',')
                ->check(CLI::IsMember({"opencv", "ffmpeg", "npy"}))
                ->capture_default_str();
            AddViewOptions(sub, &options->job.view, true);
            return [options, &context]() { RunRemap(*options, context); };
          }};
}

}  // namespace omnical::cli

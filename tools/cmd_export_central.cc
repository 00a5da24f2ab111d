// omnical export-central: the best-fit central model of a (non-central) sensor for tools
// that only take central cameras: Mei's unified model as a YAML cv::omnidir functions
// read (K, D, xi), or OCamCalib's calib_results.txt; with the approximation error over the
// field, in omni px, at the chosen object distance and at others (central_error.json/png).
// The job is correction/central_export.h.
#include <cstdio>

#include "calib/report/correction_figures.h"
#include "correction/central_export.h"
#include "tools/commands.h"
#include "tools/field_flags.h"
#include "tools/progress.h"
#include "model/io/sensor_yaml.h"

namespace omnical::cli {
namespace {

struct ExportCentralFlags {
  std::string sensor_path, model, out_dir;
  CentralExportOptions job;
};

void RunExportCentral(ExportCentralFlags& options, const Context& context) {
  const Sensor sensor = LoadSensorYaml(options.sensor_path);
  options.job.model = *ParseCentralModelKind(options.model);
  options.job.progress = TerminalProgress(context);
  const FlagTable flags = FlagsOf({"distance_mm", "n", "step_px"}, {{"v0_mm", "--v0"}});
  const CentralExportResult result = NamingFlags(flags, [&] { return ExportCentral(sensor, options.job); });
  WriteCentralExport(options.out_dir, result, options.sensor_path);
  WriteCentralExportFigures(options.out_dir, result);
  if (!context.quiet)
    std::printf("%s central model for %s, V0 = %.3f mm: %.4f px RMS, %.4f px max over %zu field samples -> %s\n",
                options.model.c_str(), result.FittedForText().c_str(), result.v0_mm, result.error.rms_px,
                result.error.max_px, result.samples.pixels.size(), options.out_dir.c_str());
}

}  // namespace

Command ExportCentralCommand() {
  return {"export-central", "Best-fit central model (Mei for cv::omnidir, or OCamCalib) with its error over the field",
          [](CLI::App& sub, const Context& context) -> CommandAction {
            auto options = std::make_shared<ExportCentralFlags>();
            CentralExportOptions& job = options->job;
            sub.add_option("--sensor", options->sensor_path, "Sensor file (YAML)")->required();
            sub.add_option("--model", options->model, "mei (cv::omnidir YAML) or ocamcalib (calib_results.txt)")
                ->required()
                ->check(CLI::IsMember({"mei", "ocamcalib"}));
            auto* d = sub.add_option("--distance-mm", job.distance_mm, "Objects on a sphere of D mm around V0 (default: infinity)");
            auto* n = sub.add_option("--n", job.n, "Objects at n mirror rim radii from V0");
            d->excludes(n);
            sub.add_option("--v0", job.v0_mm, "Viewpoint V0, z on the mirror axis (mm, mirror frame); "
                                              "default: the one minimising the worst error at the distance");
            sub.add_option("--step-px", job.step_px, "Field sampling grid, omni px")->capture_default_str();
            sub.add_option("--out", options->out_dir, "Output directory")->required();
            return [options, &context]() { RunExportCentral(*options, context); };
          }};
}

}  // namespace omnical::cli

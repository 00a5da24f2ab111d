// omnical characterize: the seed paper's evaluation of a sensor (Ohte & Tsuzuki Secs.
// 2-3 and appendix): image-forming characteristics, viewpoints, virtual images, blur
// and depth of field, as CSV, summary.json and figures in the spirit of Figs. 4-9.
// The job is model/design/characterize.h.
#include <cstdio>
#include <filesystem>

#include "calib/report/optics_figures.h"
#include "model/io/atomic_write.h"
#include "model/design/characterize.h"
#include "model/design/design_files.h"
#include "model/input_error.h"
#include "tools/commands.h"
#include "tools/field_flags.h"
#include "tools/progress.h"
#include "model/io/sensor_yaml.h"

namespace omnical::cli {
namespace {

struct Flags {
  std::string sensor_path, out_dir;
  CharacterizeOptions job;
};

void RunCharacterize(const Flags& flags, const Context& context) {
  const Sensor sensor = LoadSensorYaml(flags.sensor_path);
  const FlagTable names = {{"lens_focal_mm", "--lens-f"}, {"focus_mm", "--focus-mm"}, {"f_number", "--f-number"},
                            {"pixel_um", "--pixel-um"},    {"near_n", "--near-n"},     {"samples", "--samples"}};
  const CharacterizeResult r = NamingFlagWords(names, [&] {
    try {
      CharacterizeOptions job = flags.job;
      job.progress = TerminalProgress(context);
      return Characterize(sensor, job);
    } catch (const InputError& e) {  // "sensor: ..." is about the sensor file
      const std::string what = e.what();
      if (what.rfind("sensor: ", 0) != 0) throw;
      throw InputError(InputMessage(flags.sensor_path, "", what.substr(8)));
    }
  });
  const std::filesystem::path dir(flags.out_dir);
  CreateOutputDirectory(dir);
  WriteCharacteristicsCsv(r, (dir / "characteristics.csv").string());
  WriteCharacterizeSummaryJson(r, flags.sensor_path, (dir / "summary.json").string());
  WriteCharacterizeFigures(r, dir.string());
  if (!context.quiet)
    std::printf(
        "%s: rim Omega %.2f deg, Theta %.2f deg; viewpoint spread %.3g mm; best L0 %.1f mm, depth of field "
        "%.2f mm, worst blur %.2f px -> %s\n",
        flags.sensor_path.c_str(), r.rim_omega_deg(), r.rim_theta_deg(), r.viewpoint_spread_mm(), r.focus_mm,
        r.depth_of_field_mm, r.worst_blur_px, flags.out_dir.c_str());
}

}  // namespace

Command CharacterizeCommand() {
  return {"characterize",
          "The seed paper's evaluation of a sensor: characteristics, viewpoints, virtual images, blur, depth of field",
          [](CLI::App& sub, const Context& context) -> CommandAction {
            auto flags = std::make_shared<Flags>();
            CharacterizeOptions& o = flags->job;
            sub.add_option("--sensor", flags->sensor_path, "Sensor file (YAML)")->required();
            sub.add_option("--out", flags->out_dir, "Output directory (CSV, summary.json, PNG figures)")->required();
            sub.add_option("--lens-f", o.lens_focal_mm, "Lens focal length, mm (default: fx x pixel size)")
                ->check(kPositive);
            sub.add_option("--f-number", o.f_number, "Lens f-number F")->check(kPositive)->capture_default_str();
            sub.add_option("--pixel-um", o.pixel_um, "Pixel size, um (the permissible circle of confusion)")
                ->check(kPositive)
                ->capture_default_str();
            sub.add_option("--focus-mm", o.focus_mm, "In-focus distance L0, mm (default: searched)")->check(kPositive);
            sub.add_option("--near-n", o.near_n, "Near object distance for virtual images, mirror radii")
                ->check(kPositive)
                ->capture_default_str();
            sub.add_option("--samples", o.samples, "Samples over the mirror radius")
                ->check(CLI::Range(10, 100000))
                ->capture_default_str();
            return [flags, &context]() { RunCharacterize(*flags, context); };
          }};
}

}  // namespace omnical::cli

// omnical diff: how differently two calibrations of one camera place the same objects at a
// distance, after the best rigid alignment (calib/projection_diff.h) -> a summary on the
// terminal and, with --out, diff.json and diff.png.
#include <filesystem>

#include "calib/calibration_json.h"
#include "calib/detections.h"
#include "calib/predicted_error.h"
#include "calib/projection_diff.h"
#include "calib/report/projection_diff_figure.h"
#include "model/io/atomic_write.h"
#include "model/io/sensor_yaml.h"
#include "tools/commands.h"
#include "tools/field_flags.h"

namespace omnical::cli {
namespace {

struct DiffFlags {
  std::string a, b, field_path, out_dir;
  double distance_mm = 2000.0, step_px = 16.0, align_at_mm = NAN;
  bool no_align = false;
};

// A calibration given as its sensor file or as calibrate's output directory.
std::string SensorFileOf(const std::string& path) {
  const std::filesystem::path given(path);
  return std::filesystem::is_directory(given) ? (given / "sensor.yaml").string() : path;
}

void RunDiff(const DiffFlags& options, const Context& context) {
  const Sensor a = LoadSensorYaml(SensorFileOf(options.a));
  const Sensor b = LoadSensorYaml(SensorFileOf(options.b));
  if (a.image_width_px() != b.image_width_px() || a.image_height_px() != b.image_height_px())
    throw InputError(SensorFileOf(options.b) + ": image_size: differs from " + SensorFileOf(options.a) +
                     "'s: not calibrations of one camera");
  // The field: the corners named by --field, else those of a's calibration directory, else
  // every pixel a's mirror shows.
  std::string field_name = options.field_path;
  if (field_name.empty() && std::filesystem::is_directory(options.a) &&
      std::filesystem::exists(std::filesystem::path(options.a) / "detections.json"))
    field_name = (std::filesystem::path(options.a) / "detections.json").string();
  std::optional<DetectionSet> detections;
  if (!field_name.empty()) detections = ReadDetections(field_name);
  const FlagTable flags = FlagsOf({"distance_mm", "step_px", "align_at_mm"});
  const std::vector<Eigen::Vector2d> field =
      NamingFlags(flags, [&] { return ComparisonField(a, detections ? &*detections : nullptr, options.step_px); });
  const ProjectionDiff diff =
      NamingFlags(flags, [&] { return CompareProjections(a, b, field, options.distance_mm, !options.no_align,
                                                         options.align_at_mm); });
  const std::string field_label = field_name.empty() ? "every pixel of the mirror" : "the corners' annulus in " + field_name;
  if (!options.out_dir.empty()) {
    const std::filesystem::path dir(options.out_dir);
    CreateOutputDirectory(dir);
    // The figure first: a figure that cannot be written leaves no diff.json to mistake for a run.
    WriteProjectionDiffFigure((dir / "diff.png").string(), diff, a.image_width_px(), a.image_height_px(),
                              "b: " + SensorFileOf(options.b) + " against a: " + SensorFileOf(options.a));
    WriteProjectionDiffJson(diff,
                            {{"a", SensorFileOf(options.a)}, {"b", SensorFileOf(options.b)}, {"field", field_label}},
                            (dir / "diff.json").string());
  }
  if (context.quiet) return;
  std::printf("at %.0f mm over %d pixels (%s): RMS %.4f px, median %.4f px, max %.4f px\n", options.distance_mm,
              diff.compared, field_label.c_str(), diff.rms_px, diff.median_px, diff.max_px);
  if (diff.moved_off_mirror > 0)
    std::printf("not compared: %d field pixels, whose points the alignment fitted at %.0f mm moved off b's mirror\n",
                diff.moved_off_mirror, diff.aligned_at_mm);
  char fitted[64];
  if (diff.aligned_at_mm >= kInfinityMm) {
    std::snprintf(fitted, sizeof fitted, "fitted at infinity");
  } else {
    std::snprintf(fitted, sizeof fitted, "fitted at %.0f mm", diff.aligned_at_mm);
  }
  std::printf("alignment: %s, rotation %.4f deg, translation (%.3f, %.3f, %.3f) mm; before it: RMS %.4f px\n",
              diff.aligned        ? fitted
              : options.no_align ? "none (--no-align)"
                                 : "FAILED (the numbers are unaligned)",
              diff.rotation_deg, diff.translation_mm.x(), diff.translation_mm.y(),
              diff.translation_mm.z(), diff.unaligned_rms_px);
}

}  // namespace

Command DiffCommand() {
  return {"diff", "Compare two calibrations: their projection difference at a distance after the best rigid alignment",
          [](CLI::App& sub, const Context& context) -> CommandAction {
            auto options = std::make_shared<DiffFlags>();
            sub.add_option("a", options->a, "Reference calibration: a sensor file or calibrate's --out directory")->required();
            sub.add_option("b", options->b, "The other calibration, the same way")->required();
            sub.add_option("--distance-mm", options->distance_mm,
                           "Distance of the compared points from their reflection points, mm")
                ->check(kPositive)->capture_default_str();
            sub.add_option("--field", options->field_path,
                           "Detections (JSON) whose corners' annulus is compared (default: a's directory's "
                           "detections.json, else every pixel of the mirror)");
            sub.add_option("--step-px", options->step_px, "Grid step of the compared pixels")
                ->check(CLI::Range(1.0, 1000.0))->capture_default_str();
            sub.add_option("--align-at-mm", options->align_at_mm,
                           "Fit the rigid alignment at this distance (e.g. the boards') and apply it at --distance-mm "
                           "(default: fitted at --distance-mm)")
                ->check(kPositive);
            sub.add_flag("--no-align", options->no_align, "Compare without the rigid alignment")
                ->excludes("--align-at-mm");
            sub.add_option("--out", options->out_dir, "Output directory for diff.json and diff.png");
            return [options, &context]() { RunDiff(*options, context); };
          }};
}

}  // namespace omnical::cli

// omnical calibrate: the bundle fit of the non-central model from images (detected here)
// or detections, starting from a sensor guess or, without one, from the mirror's rim
// circle (calib/calibrate.h) -> sensor.yaml, calibration.json and a report of PNG figures.
// Everything is computed before anything is written.
#include <filesystem>
#include <sstream>
#include <thread>

#include "calib/calibrate.h"
#include "calib/calibration_json.h"
#include "calib/calibration_summary.h"
#include "calib/image_file.h"
#include "calib/report/calibration_report.h"
#include "model/io/atomic_write.h"
#include "model/model_registry.h"
#include "tools/commands.h"
#include "tools/generalisation_flags.h"
#include "tools/progress.h"
#include "model/io/sensor_yaml.h"

namespace omnical::cli {
namespace {

struct CalibrateFlags {
  std::string target_path, detections_path, images, sensor_path, out_dir, fix, tolerance, knots;
  bool checkerboard_edges = false, checkerboard_subpixel = false;  // library.checkerboard_edges: true, false, unset
  CalibrationOptions library;
};

const FlagTable kFlags = {{"fixed", "--fix"}, {"robust_loss_px", "--loss-px"}, {"loss_px", "--loss-px"},
                          {"max_iterations", "--max-iterations"}, {"tolerances", "--tolerance"}, {"profile", "--profile"},
                          {"rim_field_deg", "--rim-field-deg"}, {"guess", "--sensor"}, {"threads", "--threads"},
                          {"detection_passes", "--detection-passes"}, {"distances_mm", "--distance-mm"},
                          {"distances_n", "--distance-n"}, {"max_predicted_error_px", "--max-predicted-error-px"},
                          {"holdout_views", "--holdout"}, {"holdout", "--holdout"}, {"holdout_folds", "--holdout-folds"}, {"cross_validate", "--cross-validate"},
                          {"cross_validation_distance_mm", "--cross-validate-distance-mm"}, {"knots", "--knots"},
                          {"lens", "--lens"}, {"tangential", "--tangential"}, {"checkerboard_edges", "--checkerboard-edges"}};

void RunCalibrate(CalibrateFlags options, const Context& context) {
  CalibrationInput input;
  input.target = CalibrationTarget::FromYaml(options.target_path);
  input.target_name = options.target_path;
  if (options.images.empty() == options.detections_path.empty())
    throw InputError("calibrate: give either --images (detect here) or --detections (from omnical detect)");
  if (!options.sensor_path.empty()) {
    input.guess = LoadSensorYaml(options.sensor_path);
    input.guess_name = options.sensor_path;
    input.guess_tolerances = ReadDesignTolerances(options.sensor_path, *input.guess);
  }
  if (options.images.empty()) {
    input.detections = ReadDetections(options.detections_path);
    input.source = options.detections_path;
  } else {
    input.image_paths = ListImages(options.images);
    input.source = options.images;
  }
  CalibrationOptions& library = options.library;
  std::stringstream fix(options.fix);
  for (std::string block; std::getline(fix, block, ',');)
    if (!block.empty()) library.fixed.insert(block);
  library.tolerances = ParseDesignTolerances(options.tolerance, "--tolerance");
  if (!options.knots.empty()) library.knots = ParseKnotCount(options.knots, "--knots");
  if (options.checkerboard_edges) library.checkerboard_edges = true;
  if (options.checkerboard_subpixel) library.checkerboard_edges = false;
  library.progress = TerminalProgress(context);
  FlagTable flags = kFlags;
  if (options.checkerboard_subpixel) flags["checkerboard_edges"] = "--checkerboard-subpixel";
  const CalibrationResult result = NamingFlags(flags, [&] { return Calibrate(input, library); });

  const std::filesystem::path dir(options.out_dir);
  CreateOutputDirectory(dir);
  SaveSensorYaml(result.sensor, (dir / "sensor.yaml").string());
  if (!options.images.empty()) WriteDetections(result.detections, (dir / "detections.json").string());
  WriteCalibrationJson(result.record, (dir / "calibration.json").string());
  WriteCalibrationReport((dir / "report").string(), result, library);
  PrintWarnings(result.warnings, context);
  if (!context.quiet) std::fputs(CalibrationSummaryText(result, options.out_dir).c_str(), stdout);
}

}  // namespace

Command CalibrateCommand() {
  return {"calibrate", "Bundle fit of the non-central model from images or detections (and a guess, or the rim circle)",
          [](CLI::App& sub, const Context& context) -> CommandAction {
            auto options = std::make_shared<CalibrateFlags>();
            CalibrationOptions& library = options->library;
            sub.add_option("--target", options->target_path, "Target spec (YAML, Kalibr keys)")->required();
            sub.add_option("--images", options->images,
                           "Directory of images or a glob pattern: detect here (detections.json is written to --out)");
            sub.add_option("--detections", options->detections_path, "Detections (JSON, from omnical detect)");
            sub.add_option("--sensor", options->sensor_path,
                           "Sensor guess (YAML): nominal design values. Without it the fit starts from the mirror's "
                           "rim circle in the images (the lens chosen by held-out folds; see --lens)");
            sub.add_option("--profile", library.profile,
                           "Mirror family to fit: " + JoinChoices(ProfileNames(false)) +
                               " (a hyperboloid needs --sensor; a guess of another family is converted), or auto (the "
                               "default without a guess, with >= 4 usable views): the polynomial or the even asphere, "
                               "then through the orthographic lens a spline's knot count or none, by held-out folds")
                ->check(CLI::IsMember(CalibrationProfileNames()));
            sub.add_option("--rim-field-deg", library.rim_field_deg,
                           "Without a guess: the rim ray's angle from the mirror axis (Omega, deg) to start from")
                ->check(CLI::Range(10.0, 170.0))->capture_default_str();
            library.threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
            sub.add_option("--threads", library.threads, "Threads: detection, board checks and the fit's Jacobians (the result is the same for any count)")->check(CLI::Range(1, 256))->capture_default_str();
            sub.add_option("--out", options->out_dir, "Output directory")->required();
            sub.add_option("--fix", options->fix, "Blocks held constant: lens, lens_scale, principal_point, distortion, tangential, m, tilt, decenter, shape, poses");
            sub.add_option("--loss-px", library.loss_px, "Huber loss scale, px (0: least squares)")
                ->check(CLI::Range(0.0, 1000.0))->capture_default_str();
            sub.add_option("--max-iterations", library.max_iterations, "Solver iterations per stage")
                ->check(CLI::Range(1, 100000))->capture_default_str();
            sub.add_option("--detection-passes", library.detection_passes,
                           "With --images: pass 2 re-detects aprilgrid corners (checkerboards: refines them, searches "
                           "boardless images) through the first fit and fits again; pass 3 through the second (checkerboards: "
                           "only if it or pass 2 finds boards; one more after boards the last found); 1: a single pass")
                ->check(CLI::Range(1, 5))->capture_default_str();
            sub.add_option("--tolerance", options->tolerance,
                           "Design tolerances (one std) as weak priors, name=value,...: e.g. m_mm=2,decenter_mm=1,"
                           "tilt_deg=1,principal_point_px=10,k1=0.05 (adds to / overrides the guess file's tolerances:)");
            sub.add_option("--distance-mm", library.distances_mm,
                           "Distances (mm from the reflection point) at which to predict the projection error "
                           "(repeatable; default: the boards' median distance and infinity)")
                ->check(kPositive);
            sub.add_option("--distance-n", library.distances_n, "The same in mirror rim radii (the seed paper's n)")
                ->check(kPositive);
            sub.add_option("--max-predicted-error-px", library.max_predicted_error_px,
                           "Warn when the predicted projection error anywhere in the observed field exceeds this")
                ->check(CLI::Range(0.0, 1000.0))->capture_default_str();
            AddGeneralisationFlags(sub, &library);
            sub.add_flag("--board-warp,!--no-board-warp", library.board_warp,
                         "Fit the board's out-of-plane warp with the sensor (a paraboloid along each board axis, mm at "
                         "the centre; paper boards bend): the default; --no-board-warp holds the board flat");
            auto* edges = sub.add_flag("--checkerboard-edges", options->checkerboard_edges,
                                       "Refine checkerboard corners through the first fit by their edges (curves fitted "
                                       "across both sides of each junction), every corner: the default for a "
                                       "checkerboard's images");
            sub.add_flag("--checkerboard-subpixel", options->checkerboard_subpixel,
                         "Refine checkerboard corners by cornerSubPix on squares of 20 px and more, OpenCV's on smaller "
                         "(biased inwards near the rim); either flag is refused where it cannot apply")
                ->excludes(edges);
            sub.add_flag("--view-weights", library.view_weights,
                         "Weight each view's corners by its own noise, estimated from its residuals (views as sharp "
                         "as they are noisy: blur and JPEG near the rim); calibration.json per_view_weight");
            sub.add_option("--knots", options->knots,
                           "With --profile spline: the mirror's knot count (4..16), or auto: chosen by held-out "
                           "folds of the views (calibration.json knot_choice)");
            return [options, &context]() { RunCalibrate(*options, context); };
          }};
}

}  // namespace omnical::cli

// omnical detect: the target's corners in omni images (AprilTag 3 or OpenCV's
// checkerboard detector on the mirrored image; with --sensor, tags re-detected in virtual
// perspective views through the guess), refined to sub-pixel (calib/refine_corners.h),
// parallel over images (calib/image_detection.h); unreadable images are reported and skipped.
#include <algorithm>
#include <thread>

#include "calib/image_detection.h"
#include "calib/image_file.h"
#include "tools/commands.h"
#include "tools/progress.h"
#include "model/io/sensor_yaml.h"

namespace omnical::cli {

Command DetectCommand() {
  return {"detect", "Detect the target's corners in omni images -> detections.json (aprilgrid or checkerboard)",
          [](CLI::App& sub, const Context& context) -> CommandAction {
            auto spec = std::make_shared<std::string>();
            auto images = std::make_shared<std::string>();
            auto out = std::make_shared<std::string>();
            auto sensor_path = std::make_shared<std::string>();
            auto options = std::make_shared<DetectionOptions>();
            options->threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
            sub.add_option("--target", *spec, "Target spec (YAML, Kalibr keys)")->required();
            sub.add_option("--sensor", *sensor_path,
                           "Sensor guess (YAML): re-detect aprilgrid tags in virtual perspective views through it, refine corners in patches through it");
            sub.add_option("--images", *images, "Directory of images, or a glob pattern (quote it)")->required();
            sub.add_option("--out", *out, "Detections file (JSON)")->required();
            auto no_refine = std::make_shared<bool>(false);
            sub.add_flag("--no-refine", *no_refine,
                         "Keep the detectors' corners (no refinement of aprilgrid corners, nor of checkerboard corners "
                         "on grid steps of 20 px and more)");
            sub.add_flag("--refine-checkerboard", options->refine_checkerboards,
                         "Refine every checkerboard corner with cornerSubPix, on squares under 20 px too (sharper on "
                         "clean images; on the real Mei images the set's halves then differ more)");
            sub.add_flag("--checkerboard-edges", options->checkerboard_edges,
                         "With --sensor: refine every checkerboard corner by its edges (curves fitted across both sides "
                         "of the junction in a patch through the sensor) instead of cornerSubPix");
            sub.add_option("--threads", options->threads, "Worker threads")->check(CLI::Range(1, 256))->capture_default_str();
            return [=, &context]() {
              const CalibrationTarget target = CalibrationTarget::FromYaml(*spec);
              if (!sensor_path->empty()) options->guess = LoadSensorYaml(*sensor_path);
              options->refine = !*no_refine;
              options->progress = TerminalProgress(context);
              DetectedImages found = NamingFlags({{"guess", "--sensor"}, {"threads", "--threads"}, {"checkerboard_edges", "--checkerboard-edges"}}, [&] {
                return DetectImageFiles(target, ListImages(*images), *images, *options);
              });
              found.detections.target_spec = *spec;
              PrintWarnings(found.warnings, context);
              int corners = 0;
              for (const ImageDetections& image : found.detections.images) corners += static_cast<int>(image.corners.size());
              WriteDetections(found.detections, *out);
              if (!context.quiet)
                std::printf("%zu images, %d corners -> %s\n", found.detections.images.size(), corners, out->c_str());
            };
          }};
}

}  // namespace omnical::cli

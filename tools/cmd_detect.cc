// omnical detect: the target's corners in omni images (AprilTag 3 or OpenCV's
// checkerboard detector on the mirrored image; with --sensor, tags re-detected in virtual
// perspective views through the guess), refined to sub-pixel (calib/refine_corners.h),
// parallel over images; unreadable images are reported and skipped.
#include <glob.h>

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <iostream>
#include <mutex>
#include <optional>
#include <thread>

#include "calib/detect.h"
#include "calib/refine_corners.h"
#include "model/input_error.h"
#include "tools/commands.h"
#include "tools/progress.h"

namespace omnical::cli {
namespace {

// A directory (its images, sorted) or a glob pattern.
std::vector<std::string> ListImages(const std::string& where) {
  std::vector<std::string> paths;
  if (std::filesystem::is_directory(where)) {
    for (const auto& entry : std::filesystem::directory_iterator(where)) {
      std::string extension = entry.path().extension().string();
      std::transform(extension.begin(), extension.end(), extension.begin(), ::tolower);
      if (extension == ".png" || extension == ".pgm" || extension == ".jpg" || extension == ".jpeg" ||
          extension == ".tif" || extension == ".tiff" || extension == ".bmp")
        paths.push_back(entry.path().string());
    }
  } else {
    glob_t matches;
    if (::glob(where.c_str(), 0, nullptr, &matches) == 0)
      for (size_t i = 0; i < matches.gl_pathc; ++i) paths.push_back(matches.gl_pathv[i]);
    ::globfree(&matches);
  }
  std::sort(paths.begin(), paths.end());
  if (paths.empty()) throw InputError(InputMessage(where, "--images", "no images found (a directory or a glob pattern)"));
  return paths;
}

}  // namespace

Command DetectCommand() {
  return {"detect", "Detect the target's corners in omni images -> detections.json (aprilgrid or checkerboard)",
          [](CLI::App& sub, const Context& context) -> CommandAction {
            auto spec = std::make_shared<std::string>();
            auto images = std::make_shared<std::string>();
            auto out = std::make_shared<std::string>();
            auto threads = std::make_shared<int>(static_cast<int>(std::max(1u, std::thread::hardware_concurrency())));
            auto sensor_path = std::make_shared<std::string>();
            sub.add_option("--target", *spec, "Target spec (YAML, Kalibr keys)")->required();
            sub.add_option("--sensor", *sensor_path,
                           "Sensor guess (YAML): re-detect aprilgrid tags in virtual perspective views through it, refine corners in patches through it");
            sub.add_option("--images", *images, "Directory of images, or a glob pattern (quote it)")->required();
            sub.add_option("--out", *out, "Detections file (JSON)")->required();
            auto no_refine = std::make_shared<bool>(false);
            sub.add_flag("--no-refine", *no_refine, "Keep the detectors' corners (no sub-pixel refinement)");
            sub.add_option("--threads", *threads, "Worker threads")->check(CLI::Range(1, 256))->capture_default_str();
            return [=, &context]() {
              const bool refine = !*no_refine;
              const CalibrationTarget target = CalibrationTarget::FromYaml(*spec);
              std::optional<Sensor> guess;
              if (!sensor_path->empty()) guess = LoadSensorYaml(*sensor_path);
              const std::vector<std::string> paths = ListImages(*images);
              std::vector<ImageDetections> found(paths.size());
              std::vector<cv::Size> sizes(paths.size());
              std::vector<std::string> problems(paths.size());
              std::atomic<size_t> next{0};
              {
                Progress progress("detect", static_cast<long>(paths.size()), context.quiet);
                auto work = [&]() {
                  for (size_t i = next++; i < paths.size(); i = next++) {
                    const cv::Mat grey = cv::imread(paths[i], cv::IMREAD_GRAYSCALE);
                    if (grey.empty()) {
                      problems[i] = "cannot read the image";
                    } else {
                      sizes[i] = grey.size();
                      found[i] = DetectTarget(target, grey);
                      const bool through_guess =
                          guess && grey.cols == guess->image_width_px() && grey.rows == guess->image_height_px();
                      if (through_guess && target.type() == CalibrationTarget::Type::kAprilGrid)
                        found[i] = DetectThroughVirtualViews(target, grey, *guess, found[i]);
                      if (refine) found[i] = RefineCorners(target, grey, through_guess ? &*guess : nullptr, found[i]);
                      found[i].image = paths[i];
                    }
                    progress.Advance();
                  }
                };
                std::vector<std::thread> pool;
                for (int t = 1; t < *threads; ++t) pool.emplace_back(work);
                work();
                for (std::thread& t : pool) t.join();
              }
              DetectionSet set;
              set.target_spec = *spec;
              int corners = 0;
              for (size_t i = 0; i < paths.size(); ++i) {
                if (problems[i].empty() && set.images.empty()) {
                  set.image_width_px = sizes[i].width;
                  set.image_height_px = sizes[i].height;
                }
                if (problems[i].empty() && sizes[i] != cv::Size(set.image_width_px, set.image_height_px))
                  problems[i] = "its size differs from the first image's";
                if (!problems[i].empty()) {
                  std::cerr << "omnical: warning: " << paths[i] << ": " << problems[i] << ", skipped\n";
                  continue;
                }
                corners += static_cast<int>(found[i].corners.size());
                set.images.push_back(found[i]);
              }
              if (set.images.empty()) throw InputError(InputMessage(*images, "--images", "no readable image"));
              WriteDetections(set, *out);
              if (!context.quiet)
                std::printf("%zu images, %d corners -> %s\n", set.images.size(), corners, out->c_str());
            };
          }};
}

}  // namespace omnical::cli

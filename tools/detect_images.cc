#include "tools/detect_images.h"
#include "tools/cli_common.h"

#include <glob.h>

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <iostream>
#include <thread>

#include "calib/detect.h"
#include "calib/refine_corners.h"
#include "model/input_error.h"
#include "tools/progress.h"

namespace omnical::cli {

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

DetectedImages DetectImages(const CalibrationTarget& target, const std::string& target_spec_path,
                            const std::string& images, const ImageDetectionOptions& options) {
  const std::vector<std::string> paths = ListImages(images);
  std::vector<ImageDetections> found(paths.size());
  std::vector<cv::Size> sizes(paths.size());
  std::vector<std::string> problems(paths.size());
  std::vector<std::optional<RimCircle>> circles(paths.size());
  std::vector<std::vector<std::string>> refusals(paths.size());  // checkerboard candidates refused, per image
  std::atomic<size_t> next{0};
  {
    Progress progress("detect", static_cast<long>(paths.size()), options.quiet);
    auto work = [&]() {
      for (size_t i = next++; i < paths.size(); i = next++) {
        const cv::Mat grey = ReadImage(paths[i], cv::IMREAD_GRAYSCALE);
        if (grey.empty()) {
          problems[i] = "cannot read the image";
        } else {
          sizes[i] = grey.size();
          if (target.type() == CalibrationTarget::Type::kCheckerboard) {
            std::vector<CheckerboardCandidate> candidates;
            found[i] = DetectCheckerboard(target, grey, &candidates);
            for (const CheckerboardCandidate& c : candidates)
              if (!c.accepted) refusals[i].push_back(c.refusal);
          } else {
            found[i] = DetectTarget(target, grey);
          }
          const Sensor* guess = options.guess && grey.cols == options.guess->image_width_px() &&
                                        grey.rows == options.guess->image_height_px()
                                    ? options.guess
                                    : nullptr;
          if (guess && target.type() == CalibrationTarget::Type::kAprilGrid)
            found[i] = DetectThroughVirtualViews(target, grey, *guess, found[i]);
          const bool checkerboard = target.type() == CalibrationTarget::Type::kCheckerboard;
          if (checkerboard ? options.refine_checkerboards : options.refine)
            found[i] = RefineCorners(target, grey, guess, found[i]);
          if (options.rim_circles) circles[i] = DetectRimCircle(grey);
          found[i].image = paths[i];
        }
        progress.Advance();
      }
    };
    std::vector<std::thread> pool;
    for (int t = 1; t < options.threads; ++t) pool.emplace_back(work);
    work();
    for (std::thread& t : pool) t.join();
  }
  DetectedImages out;
  out.detections.target_spec = target_spec_path;
  for (size_t i = 0; i < paths.size(); ++i) {
    if (problems[i].empty() && out.detections.images.empty()) {
      out.detections.image_width_px = sizes[i].width;
      out.detections.image_height_px = sizes[i].height;
    }
    if (problems[i].empty() && sizes[i] != cv::Size(out.detections.image_width_px, out.detections.image_height_px))
      problems[i] = "its size differs from the first image's";
    for (const std::string& why : refusals[i])
      std::cerr << "omnical: warning: " << paths[i] << ": a checkerboard-like grid refused: " << why << "\n";
    if (!problems[i].empty()) {
      std::cerr << "omnical: warning: " << paths[i] << ": " << problems[i] << ", skipped\n";
      continue;
    }
    out.detections.images.push_back(found[i]);
    if (circles[i]) out.rim_circles.push_back(*circles[i]);
  }
  if (out.detections.images.empty()) throw InputError(InputMessage(images, "--images", "no readable image"));
  return out;
}

}  // namespace omnical::cli

#include "calib/image_detection.h"

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <functional>

#include "calib/detect.h"
#include "calib/image_file.h"
#include "calib/refine_corners.h"
#include "model/input_error.h"
#include "model/parallel_rows.h"

namespace omnical {
namespace {

struct OneImage {
  ImageDetections found;
  cv::Size size;
  std::string problem;  // why it is skipped
  std::optional<RimCircle> circle;
  std::vector<std::string> refusals;  // checkerboard candidates refused
};

// The guess when the image has its size, else none.
const Sensor* GuessFor(const cv::Mat& grey, const DetectionOptions& options) {
  return options.guess && grey.cols == options.guess->image_width_px() && grey.rows == options.guess->image_height_px()
             ? &*options.guess
             : nullptr;
}

ImageDetections Refined(const CalibrationTarget& target, const cv::Mat& grey, const Sensor* guess,
                        const DetectionOptions& options, const ImageDetections& found) {
  const bool checkerboard = target.type() == CalibrationTarget::Type::kCheckerboard;
  if (!options.refine && !(checkerboard && (options.refine_checkerboards || options.checkerboard_edges))) return found;
  return RefineCorners(target, grey, guess, found, nullptr,
                       checkerboard && !options.refine_checkerboards ? kMinRefinedCheckerStepPx : 0.0,
                       options.checkerboard_edges ? CheckerRefinement::kEdges : CheckerRefinement::kSubPixel,
                       options.fit_whole_tags, options.board_warp);
}

void DetectOne(const CalibrationTarget& target, const cv::Mat& grey, const DetectionOptions& options, OneImage* out) {
  if (grey.empty()) {
    out->problem = "cannot read the image";
    return;
  }
  out->size = grey.size();
  const bool checkerboard = target.type() == CalibrationTarget::Type::kCheckerboard;
  const Sensor* guess = GuessFor(grey, options);
  const bool omni_search = options.omni_search || !guess;
  if (omni_search && checkerboard) {
    std::vector<CheckerboardCandidate> candidates;
    out->found = DetectCheckerboard(target, grey, &candidates);
    for (const CheckerboardCandidate& c : candidates)
      if (!c.accepted) out->refusals.push_back(c.refusal);
  } else if (omni_search) {
    out->found = DetectTarget(target, grey);
  }
  if (guess) out->found = DetectThroughVirtualViews(target, grey, *guess, out->found);
  out->found = Refined(target, grey, guess, options, out->found);
  if (options.rim_circles) out->circle = DetectRimCircle(grey);
}

// one(i) for i in [0, count) on options.threads threads, one progress step each (stage
// `stage`). What `one` throws stops the images not yet started and is rethrown here once
// every thread has stopped (on a worker thread it would end the process); so is what the
// progress callback threw, or Cancelled.
void PerImage(size_t count, const DetectionOptions& options, const char* stage,
              const std::function<void(size_t)>& one) {
  ProgressReporter progress(options.progress, stage, static_cast<long>(count));
  ParallelRows(static_cast<int>(count), options.threads, [&](int i) {
    one(static_cast<size_t>(i));
    if (!progress.Advance()) progress.ThrowIfCancelled();
  });
}

// Detects image i of `count` (get(i) gives its pixels, name(i) its name) on
// options.threads threads, then collects the results in order.
DetectedImages DetectAll(const CalibrationTarget& target, size_t count, const std::function<cv::Mat(size_t)>& get,
                         const std::function<std::string(size_t)>& name, const std::string& source,
                         const DetectionOptions& options) {
  if (const std::string why = options.Check(); !why.empty()) throw InputError(why);
  std::vector<OneImage> images(count);
  PerImage(count, options, "detect", [&](size_t i) {
    // An image the decoder or a detector chokes on (OpenCV throws on some corrupt files
    // and absurd sizes) is skipped like an unreadable one, not the whole set.
    try {
      DetectOne(target, get(i), options, &images[i]);
    } catch (const cv::Exception& error) {
      images[i] = OneImage{};
      images[i].problem = "OpenCV failed on it (" + error.err + ")";
    }
    images[i].found.image = name(i);
  });

  DetectedImages out;
  out.detections.target_description = target.Describe();
  for (size_t i = 0; i < count; ++i) {
    OneImage& image = images[i];
    if (image.problem.empty() && out.detections.images.empty()) {
      out.detections.image_width_px = image.size.width;
      out.detections.image_height_px = image.size.height;
    }
    if (image.problem.empty() && image.size != cv::Size(out.detections.image_width_px, out.detections.image_height_px))
      image.problem = "its size differs from the first image's";
    for (const std::string& why : image.refusals)
      out.warnings.push_back({WarningCode::kCheckerboardRefused, name(i), name(i) + ": a checkerboard-like grid refused: " + why});
    if (!image.problem.empty()) {
      out.warnings.push_back({image.size.empty() ? WarningCode::kImageUnreadable : WarningCode::kImageSizeDiffers, name(i),
                              name(i) + ": " + image.problem + ", skipped", image.problem});
      continue;
    }
    out.detections.images.push_back(std::move(image.found));
    if (image.circle) out.rim_circles.push_back(*image.circle);
  }
  if (out.detections.images.empty()) throw InputError(InputMessage(source, "images", "no readable image"));
  return out;
}

}  // namespace

std::string DetectionOptions::Check() const {
  // The guess is not validated here: a sensor file is when read, and the second detection
  // pass of a calibration goes through a fitted sensor that may fail validation (the
  // calibration then warns) yet still places the patches well.
  if (threads < 1) return "threads: must be >= 1 (got " + std::to_string(threads) + ")";
  if (checkerboard_edges && !guess)
    return "checkerboard_edges/guess: the corners are refined by their edges in patches through a sensor guess: give one";
  return "";
}

DetectedImages DetectImageFiles(const CalibrationTarget& target, const std::vector<std::string>& paths,
                                const std::string& source, const DetectionOptions& options) {
  return DetectAll(
      target, paths.size(), [&](size_t i) { return ReadImageFile(paths[i], cv::IMREAD_GRAYSCALE); },
      [&](size_t i) { return paths[i]; }, source, options);
}

DetectionSet RefineFoundCorners(const CalibrationTarget& target, const DetectionSet& found,
                                const std::function<cv::Mat(const std::string&)>& image_of,
                                const DetectionOptions& options) {
  if (const std::string why = options.Check(); !why.empty()) throw InputError(why);
  DetectionSet out = found;
  PerImage(found.images.size(), options, "refine", [&](size_t i) {
    const cv::Mat grey = image_of(found.images[i].image);
    if (!grey.empty() && grey.type() == CV_8UC1) {
      out.images[i] = Refined(target, grey, GuessFor(grey, options), options, found.images[i]);
    } else {  // predictions stand only once refined
      auto& corners = out.images[i].corners;
      corners.erase(std::remove_if(corners.begin(), corners.end(), [](const CornerObservation& c) { return c.predicted; }),
                    corners.end());
    }
  });
  return out;
}

DetectedImages DetectImages(const CalibrationTarget& target, const std::vector<NamedImage>& images,
                            const DetectionOptions& options) {
  for (const NamedImage& image : images)
    if (!image.grey.empty() && image.grey.type() != CV_8UC1)
      throw InputError(InputMessage(image.name, "image", "must be 8-bit grey (one channel)"));
  return DetectAll(
      target, images.size(), [&](size_t i) { return images[i].grey; }, [&](size_t i) { return images[i].name; },
      "images", options);
}

}  // namespace omnical

// The target's corners in many omni images: parallel, with progress through a callback;
// an unreadable image or one of another size is reported (a warning) and skipped.
// Optionally the mirror's rim circle of every image (calibration without a guess starts
// from it). Images come as files or as cv::Mat.
#pragma once

#include <opencv2/core.hpp>

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "calib/board_warp.h"
#include "calib/calibration_warning.h"
#include "calib/detections.h"
#include "calib/rim_circle.h"
#include "calib/target.h"
#include "model/progress.h"
#include "model/sensor.h"

namespace omnical {

struct DetectionOptions {
  std::optional<Sensor> guess;        // virtual views (calib/detect.h) and patch refinement through it
  // Sub-pixel refinement (calib/refine_corners.h): aprilgrid corners, and checkerboard
  // corners on grid steps of kMinRefinedCheckerStepPx and more.
  bool refine = true;
  // Every checkerboard corner, small squares too (on the real Mei images it made the
  // halves of the set differ more: calib/refine_corners.h).
  bool refine_checkerboards = false;
  // With a guess: checkerboard corners refined by their edges, every one (calib/refine_corners.h).
  bool checkerboard_edges = false;
  // With a guess: aprilgrid tags fitted whole (calib/tag_template_fit.h) after the edge profiles.
  bool fit_whole_tags = true;
  // The board's warp (calib/board_warp.h) the pieces fitted whole (tags, checkerboard
  // junctions the edges cannot read) bend by: a calibration's previous fit's. Flat, a
  // realistic render's 3 mm bend put mid-field junctions 0.047 px off the truth, bent 0.009.
  BoardWarp board_warp;
  bool rim_circles = false;
  // false: with a guess, search its virtual views only (images the omni image's search
  // already missed: a second pass through a fitted sensor).
  bool omni_search = true;
  int threads = 1;
  ProgressCallback progress;  // stage "detect", one step per image
  std::string Check() const;  // "" or "field: problem"
};

struct DetectedImages {
  DetectionSet detections;                  // target_spec is left to the caller
  std::vector<RimCircle> rim_circles;       // of the images where one was found
  std::vector<CalibrationWarning> warnings;  // images skipped, grids refused
};

// An image in memory and the name it is reported under (its path, or any label).
struct NamedImage {
  std::string name;
  cv::Mat grey;  // 8-bit, one channel
};

// Corners found earlier without refinement (options.refine off) refined in their images
// (calib/refine_corners.h) through options.guess, as DetectOne would have: a calibration
// refines its checkerboard corners through its first fit, not through the design guess
// (there, at large radii, patches through a misaligned guess moved corners OpenCV had to
// 0.01-0.08 px by 0.1-0.7 px). image_of(name) gives an entry's pixels (8-bit grey; empty:
// the entry is kept as it is). Parallel on options.threads, progress stage "refine".
DetectionSet RefineFoundCorners(const CalibrationTarget& target, const DetectionSet& found,
                                const std::function<cv::Mat(const std::string&)>& image_of,
                                const DetectionOptions& options);

// Throws InputError naming `source` (the directory or pattern) if no image could be read.
DetectedImages DetectImageFiles(const CalibrationTarget& target, const std::vector<std::string>& paths,
                                const std::string& source, const DetectionOptions& options);
DetectedImages DetectImages(const CalibrationTarget& target, const std::vector<NamedImage>& images,
                            const DetectionOptions& options);

}  // namespace omnical

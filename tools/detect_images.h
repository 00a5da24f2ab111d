// Detection over many images for `detect` and `calibrate --images`: parallel, with
// progress; an unreadable image or one of another size is reported and skipped. Optionally
// the mirror's rim circle of every image (calibration without a guess starts from it).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "calib/detections.h"
#include "calib/rim_circle.h"
#include "calib/target.h"
#include "model/sensor.h"

namespace omnical::cli {

// A directory (its images, sorted) or a glob pattern. Throws InputError if nothing matches.
std::vector<std::string> ListImages(const std::string& where);

struct ImageDetectionOptions {
  const Sensor* guess = nullptr;  // virtual views and patch refinement through it
  bool refine = true;                 // aprilgrid corners (calib/refine_corners.h)
  bool refine_checkerboards = false;  // see calib/refine_corners.h: better on renders, worse on real images
  bool rim_circles = false;
  int threads = 1;
  bool quiet = false;
};

struct DetectedImages {
  DetectionSet detections;
  std::vector<RimCircle> rim_circles;  // the images where one was found
};

// Throws InputError if no image could be read.
DetectedImages DetectImages(const CalibrationTarget& target, const std::string& target_spec_path,
                            const std::string& images, const ImageDetectionOptions& options);

}  // namespace omnical::cli

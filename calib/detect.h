// Target detection in omni images. A mirror reverses handedness, so tags appear
// mirror-imaged: the image is flipped horizontally, AprilTag 3 detects there, and the
// corners are mapped back. Tag corner k of AprilTag's detection is the board's corner k
// (calib/target.h; Kalibr's order), checked on a printed board in tests/detect_test.cc.
//
// Not yet: re-detection in virtual perspective views through a sensor guess (for tags
// near the rim), sub-pixel refinement beyond AprilTag's edge refinement, checkerboards.
#pragma once

#include <opencv2/core.hpp>

#include <string>

#include "calib/detections.h"
#include "calib/target.h"

namespace omnical {

struct DetectionStats {
  int tags = 0;         // tags accepted
  int wrong_ids = 0;    // decoded ids the target does not have
  int duplicates = 0;   // ids seen twice (all copies dropped)
};

// Detects the target's tags in an 8-bit grey image (pixel-centre coordinates, as
// everywhere). Throws std::invalid_argument for a target type it cannot detect yet.
ImageDetections DetectAprilGrid(const CalibrationTarget& target, const cv::Mat& grey, DetectionStats* stats = nullptr);

}  // namespace omnical

// Target detection in omni images. A mirror reverses handedness, so tags appear
// mirror-imaged: the image is flipped horizontally, AprilTag 3 detects there, and the
// corners are mapped back. Tag corner k of AprilTag's detection is the board's corner k
// (calib/target.h; Kalibr's order), checked on a printed board in tests/detect_test.cc.
//
// Checkerboards: OpenCV's findChessboardCornersSB (EXHAUSTIVE | ACCURACY) on the flipped
// image, repeated until every candidate grid is found (calib/checkerboard_candidates.h).
// Its row-major order is read with rows counted upwards, which makes the id assignment a
// proper rotation of the board. The remaining 180 deg turn (the grid's corner set maps onto
// itself, so a fit is unaffected, but the pose turns) is resolved by the print's colours
// where the board has them (cols + rows odd), else by a convention: rows count up away from
// the image centre (an upright board around a vertical mirror axis).
//
// Sub-pixel refinement of what these find: calib/refine_corners.h.
#pragma once

#include <opencv2/core.hpp>

#include <string>
#include <vector>

#include "calib/checkerboard_candidates.h"
#include "calib/detections.h"
#include "calib/target.h"
#include "model/sensor.h"

namespace omnical {

struct DetectionStats {
  int tags = 0;         // tags accepted
  int wrong_ids = 0;    // decoded ids the target does not have
  int duplicates = 0;   // ids seen twice (all copies dropped)
};

// Detects the target's tags in an 8-bit grey image (pixel-centre coordinates, as
// everywhere). Throws std::invalid_argument for another target type.
// `mirrored`: the image is a mirror's (an omni image); false for unwarped virtual screens.
ImageDetections DetectAprilGrid(const CalibrationTarget& target, const cv::Mat& grey, DetectionStats* stats = nullptr,
                                bool mirrored = true);

// The checkerboard's inner corners, all or none. Candidate grids are searched for until
// one is accepted (up to three searches, calib/checkerboard_candidates.h), and one that is
// a patch of a larger checker pattern (tiles, a checked floor) is refused; a grid that is
// not, but shows another board than the other views (a wrongly sized decoy), is for the
// fit's board checks (calib/board_scale.h). `candidates` (optional) receives every candidate with
// its refusal reason, for the caller's warnings. Throws std::invalid_argument for another
// target type.
ImageDetections DetectCheckerboard(const CalibrationTarget& target, const cv::Mat& grey,
                                   std::vector<CheckerboardCandidate>* candidates = nullptr);

// Either, by the target's type.
ImageDetections DetectTarget(const CalibrationTarget& target, const cv::Mat& grey);

// The target through virtual perspective views built with a sensor guess, resampled from
// the omni image with maps of exact projections, so that what is found there maps back
// through the same maps and the guess's error does not move it.
// AprilTag grids: a sweep of pinhole views (magnified ~2x, from the mirror's reference
// viewpoint); tags are detected there (no mirror reversal in a perspective view). Per tag,
// the view where it is most central wins; tags found only in the omni image are kept from
// `raw`; then tags no view could decode are placed from the decoded ones
// (calib/aprilgrid_completion.h).
// Checkerboards, only when `raw` has none (all or none per image): a sweep of wide views
// (90 deg) where a board curved near the rim or the inner radius is nearly straight, then
// a view aimed at the board found; ids as in DetectCheckerboard. `raw` otherwise.
ImageDetections DetectThroughVirtualViews(const CalibrationTarget& target, const cv::Mat& grey, const Sensor& guess,
                                          const ImageDetections& raw);

}  // namespace omnical

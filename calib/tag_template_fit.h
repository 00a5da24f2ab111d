// An aprilgrid tag's four corners from every pixel around it: the printed pattern (black
// square, data bits, white gap, as the target spec prints it) fitted whole to the omni
// image (calib/printed_patch_fit.h) over the pixels within one cell of the tag's black
// square, from a pose by PnP on the given corners; the corners are the fitted pose's,
// projected through the sensor.
#pragma once

#include <Eigen/Core>
#include <array>
#include <opencv2/core.hpp>

#include "calib/board_warp.h"
#include "calib/target.h"
#include "model/sensor.h"

namespace omnical {

// A tag's corner fitted whole away from the rim is kept only this far inside the sensor's
// rim and more (a pixel box; nearer, the tag is fitted across the rim instead): on the
// realistic aprilgrid renders one 1 px inside the sensor's rim lay beyond the render's.
constexpr int kCornerRimMarginPx = 2;

// A tag's corner fitted across the rim is kept this far inside the rim the fit placed
// (PatchFit::rim_shift_px) and more. That rim is within ~0.2 px of the image's (a sensor's
// rim moved 1.8-1.9 px: fitted shifts 1.75-1.85 px, TagTemplateFit.KeepsRimCornersByTheRimItFitted);
// over 6 realistic aprilgrid seeds the corners kept 1-2 px inside the true rim came out
// 0.11 px RMS from the truth (0.17 worst), those 2-3 px inside 0.066 px, mid-field 0.05.
constexpr double kFittedRimMarginPx = 1.0;

// How far (cells of the tag's longest side) a whole-tag fit may move a corner that started
// where the detector put it (its edge profiles failed), and one the edge profiles placed.
constexpr double kDetectorCornerMaxMoveCells = 1.25;
constexpr double kRefinedCornerMaxMoveCells = 0.5;

struct TagTemplateFit {
  std::array<Eigen::Vector2d, 4> corners_px;  // corner ids 4 tag + k, k = 0..3 (calib/target.h)
  // Across the rim: which corners lie on the mirror, kFittedRimMarginPx and more inside the
  // fitted rim (the others' corners_px are where the mirror would show them were it wider).
  std::array<bool, 4> on_mirror = {true, true, true, true};
  double blur_px = 0.0;                       // the fitted Gaussian's sigma, omni px
  double contrast = 0.0;                      // paper - ink, grey levels
  double rms_grey = 0.0;                      // the fit's residual RMS, grey levels
  int pixels = 0;                             // fitted pixels
  double rim_shift_px = 0.0;                  // across the rim: PatchFit::rim_shift_px
};

// Fits the tag with id `tag` (its corners' ids 4 tag + k) of an aprilgrid (tag36h11: a
// black square of 8 cells with a white ring around, target.Reflectance) on a board bent by
// `warp`, from `start_px`, its corners in the omni image `grey` (8-bit). False when it
// cannot: too few pixels on the mirror, the fit does not converge, no contrast, the pattern
// does not match (residual over a quarter of the contrast), an implausible blur, or a
// corner moved more than its max_move_cells of a cell (of the tag's longest side).
// across_rim: a tag the mirror's rim cuts (calib/checkerboard_completion.h predicts it):
// start_px may lie beyond the rim (where a wider mirror would show them), the rim is
// modelled instead of kept clear of; a corner must lie within kRimClearancePx of the rim (a
// pixel whose ray passes beyond it) and one on the mirror.
// Elsewhere no corner may lie within kRimClearancePx of the rim.
bool FitTagTemplate(const CalibrationTarget& target, const cv::Mat& grey, const Sensor& sensor, const BoardWarp& warp,
                    int tag, const std::array<Eigen::Vector2d, 4>& start_px, TagTemplateFit* fit,
                    bool across_rim = false, const std::array<double, 4>& max_move_cells = {kRefinedCornerMaxMoveCells, kRefinedCornerMaxMoveCells,
                                                                                     kRefinedCornerMaxMoveCells, kRefinedCornerMaxMoveCells});

}  // namespace omnical

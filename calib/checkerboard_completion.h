// Corners the detector missed, predicted through a fit (calibrate's previous pass).
// OpenCV's detector and the partial-board search need whole squares around a junction, and
// AprilTag decodes no tag the rim cuts, so where the mirror's rim crosses a board its outer
// row shows but is not found (the realistic renders lost 13 of 570 checkerboard and 17 of
// 1692 aprilgrid corners that way, every one on a row the rim cuts). Each missing corner
// is projected through the fitted sensor and its board's pose and warp, marked
// `predicted`, and kept only where calib/refine_corners.h confirms it: a checkerboard's by
// its edges (CheckerRefinement::kEdges: both grid lines through the junction found on both
// sides of it) or, where the rim cuts one side, by its squares fitted whole
// (calib/checker_junction_fit.h), within a quarter square of the prediction; a tag's by
// its pattern fitted whole across the rim (calib/tag_template_fit.h). A prediction off the
// board (a corner beyond the rim, behind a hand) is not confirmed and is dropped.
#pragma once

#include "calib/board_warp.h"
#include "calib/bundle_fit.h"
#include "calib/detections.h"
#include "calib/target.h"
#include "model/sensor.h"

namespace omnical {

// `found` with predictions (`predicted`) added to the image of each view of `fitted` (the
// views `fit` was given, in its order; matched to `found` by image name) that the fit kept:
// every board corner that image of `found` lacks, through `sensor`, the view's fitted pose
// and `warp` (the board's: fitted or held). `found` as it is for another target type.
// Throws std::logic_error when `fit` does not describe `fitted`'s views.
DetectionSet WithPredictedCheckerCorners(const CalibrationTarget& target, const Sensor& sensor, const BoardWarp& warp,
                                         const DetectionSet& fitted, const FitResult& fit, DetectionSet found);

// The same for an aprilgrid's tags the rim cuts (AprilTag decodes none of them, and a tag
// with a corner found but not all four is not fitted whole): for each tag of a fitted view
// with under four corners found and one or more on the mirror through the fit, its missing
// corners predicted where a wider mirror of the same shape would show them, so that
// calib/refine_corners.h fits the tag across the rim and keeps the corners the mirror shows
// (a prediction without such a fit is dropped). `found` as it is for another target type.
DetectionSet WithPredictedTagCorners(const CalibrationTarget& target, const Sensor& sensor, const BoardWarp& warp,
                                     const DetectionSet& fitted, const FitResult& fit, DetectionSet found);

}  // namespace omnical

// Checkerboard corners the detector missed, predicted through a fit (calibrate's previous
// pass). OpenCV's detector and the partial-board search need whole squares around a
// junction, so where the mirror's rim cuts a board the outer row of junctions shows but is
// not found (the realistic checkerboard render lost 13 of its 570 visible corners that way,
// every one on a row the rim cuts). Each board corner a fitted view lacks is projected through the fitted sensor
// and its board's pose and warp, marked `predicted`, and kept only where its refinement by
// edges (CheckerRefinement::kEdges, calib/refine_corners.h) succeeds: both grid lines
// through the junction found on both sides of it, smooth to a small fraction of a square,
// the crossing within a quarter square of the prediction. A prediction off the board (a
// corner beyond the rim, behind a hand) finds no such junction and is dropped.
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

}  // namespace omnical

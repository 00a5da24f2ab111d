// Checkerboard corners the detector missed, predicted through a fit. OpenCV's detector and
// the partial-board search need whole squares around a junction, so where the mirror's rim
// cuts a board the outer row of junctions shows but is not found (the realistic
// checkerboard render lost 13 of its 570 visible corners that way, every one on a row the
// rim cuts). Each board corner a fitted view lacks is projected through the fitted sensor
// and its board's pose and warp, marked `predicted`, and kept only where its refinement by
// edges (CheckerRefinement::kEdges, calib/refine_corners.h) succeeds: both grid lines
// through the junction found on both sides of it, smooth to a small fraction of a square,
// the crossing within a quarter square of the prediction. A prediction off the board (a
// corner beyond the rim, behind a hand) finds no such junction and is dropped.
#pragma once

#include "calib/bundle_fit.h"
#include "calib/detections.h"
#include "calib/target.h"
#include "model/sensor.h"

namespace omnical {

// `found` with the corners each view of `fitted` (the views `fit` was given, in its order)
// lacks added as predictions (`predicted`), for the views the fit kept. `found` as it is
// for another target type.
DetectionSet WithPredictedCheckerCorners(const CalibrationTarget& target, const Sensor& sensor,
                                         const DetectionSet& fitted, const FitResult& fit, DetectionSet found);

}  // namespace omnical

// Which of a fit's views show a board of another size than the target (calib/board_scale.h),
// each view checked through the fitted sensor, and a suspect once more through a sensor fitted
// without it: a decoy bends the sensor it is checked through towards its own size. Measured: a
// distant giant 4 x the board, one of 12 views, fit best at 1.56 x its size through the fit it
// was in (under the 1.65 refusal ratio), and far beyond through the fit without it.
#pragma once

#include <vector>

#include "calib/board_scale.h"
#include "calib/bundle_fit.h"
#include "calib/detections.h"
#include "calib/fit_options.h"
#include "calib/target.h"
#include "model/sensor.h"

namespace omnical {

struct BoardSizeScreenOptions {
  BoardScaleOptions scale;
  // A view not refused whose best size lies beyond this ratio (either way) and fits better
  // there by more than scale.min_chi2 is a suspect; the farthest one is checked again
  // through a fit without it. True boards have fitted best at 0.66-1.43 x (1.52 as a ratio).
  double suspect_ratio = 1.25;
  int threads = 1;
};

struct BoardSizeScreen {
  std::vector<BoardScale> checks;  // per view of the detections (a default one for a view the fit left out)
  std::vector<size_t> refused;     // views refused, ascending
  // The suspect's re-check, when there was one (no view refused directly): its view and the
  // check through the fit without it.
  int suspect = -1;
  BoardScale suspect_check;
};

// `fit` from FitSensor(start, target, detections, poses, fit_options); the suspect's fit
// without it starts from `start` and fit.poses.
BoardSizeScreen ScreenBoardSizes(const Sensor& start, const CalibrationTarget& target, const DetectionSet& detections,
                                 const FitResult& fit, const FitOptions& fit_options,
                                 const BoardSizeScreenOptions& options = {});

}  // namespace omnical

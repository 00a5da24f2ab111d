// Which of a fit's views show a board of another size than the target (calib/board_scale.h),
// each view checked through the fitted sensor, and, when none is refused that way, the
// strongest suspect once more through a sensor fitted without it: a decoy bends the sensor
// it is checked through towards its own size. Measured: a distant giant 4 x the board, one
// of 12 views, fit best at 1.56 x its size through the fit it was in (under the 1.65
// refusal ratio), at 3.87 x through the fit without it. Only the strongest: a true board
// checked through a fit without it but with the giant still in fit best at 0.60 x and was
// refused. After a refusal the caller refits without the refused views and screens again
// (calib/calibrate.cc), so decoys go one by one, the strongest first.
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
  // there by more than scale.min_chi2 is a suspect; the one whose best size fits better by
  // the most (chi2_gain) is checked again. Not the one farthest in size: true boards have
  // fitted best at 0.64-0.70 x their size through a giant's fit (a ratio of up to 1.56),
  // the 4x giant at 1.56 x; in chi2 the giant stood out (~3000 against 199,
  // tests/calibration_trust_test.cc).
  double suspect_ratio = 1.25;
  int threads = 1;
};

struct BoardSizeScreen {
  std::vector<BoardScale> checks;  // per view of the detections (a default one for a view the fit left out)
  std::vector<size_t> refused;     // views refused, ascending
  // The view checked again through a fit without it (no view refused directly, and one
  // qualified); -1 when none. Refused that way, its entry in `checks` is that check.
  int suspect = -1;
};

// `fit` from FitSensor(start, target, detections, poses, fit_options); the suspect's fit
// without it starts from `start` and fit.poses.
BoardSizeScreen ScreenBoardSizes(const Sensor& start, const CalibrationTarget& target, const DetectionSet& detections,
                                 const FitResult& fit, const FitOptions& fit_options,
                                 const BoardSizeScreenOptions& options = {});

}  // namespace omnical

// The few lines a person reads after a calibration (what `omnical calibrate` prints and
// CalibrationResult.summary() returns in Python): the start, the RMS, each parameter with
// its std, and the optional warp, held-out and two-halves results. Front ends print it;
// the library never does.
#pragma once

#include <string>

#include "calib/calibrate.h"

namespace omnical {

// Lines end in '\n'. `destination` (e.g. the output directory) is named on the RMS line
// when not empty.
std::string CalibrationSummaryText(const CalibrationResult& result, const std::string& destination = "");

}  // namespace omnical

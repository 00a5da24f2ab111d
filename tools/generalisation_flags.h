// calibrate's flags asking how well a calibration generalises (calib/cross_validation.h):
// held-out views, every view held out in folds, two halves, leave-one-out; and the lens
// of an unknown mirror, which --lens auto chooses by held-out folds.
#pragma once

#include <CLI/CLI.hpp>

#include "calib/calibrate.h"

namespace omnical::cli {

void AddGeneralisationFlags(CLI::App& sub, CalibrationOptions* library);

}  // namespace omnical::cli

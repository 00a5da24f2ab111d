// calibrate's flags asking how well a calibration generalises (calib/cross_validation.h):
// held-out views, every view held out in folds, two halves, leave-one-out; and the model
// choices made by held-out folds: --lens auto (an unknown mirror's lens) and --tangential
// auto (a pinhole's p1, p2).
#pragma once

#include <CLI/CLI.hpp>

#include "calib/calibrate.h"

namespace omnical::cli {

void AddGeneralisationFlags(CLI::App& sub, CalibrationOptions* library);

}  // namespace omnical::cli

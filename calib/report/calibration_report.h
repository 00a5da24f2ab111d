// The calibration report's figures (DIR/report/): residual vectors on every fitted image,
// the corners' coverage, a histogram of residual magnitudes, the RMS per view, and a map
// of the predicted projection error per distance.
#pragma once

#include <string>

#include "calib/calibrate.h"

namespace omnical {

// Writes the PNGs into `dir` (created); throws InputError naming a file it cannot write.
// The residuals are drawn on the views' pictures: `images` when the calibration was given
// images in memory (CalibrationInput::images, matched by name), else the files the views
// name; a view without either gets a grey background.
void WriteCalibrationReport(const std::string& dir, const CalibrationResult& result, const CalibrationOptions& options,
                            const std::vector<NamedImage>& images = {});

}  // namespace omnical

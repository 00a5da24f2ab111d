// The figure of a projection difference (calib/projection_diff.h): over the image, each
// compared field pixel's cell coloured by |difference| and an arrow along the difference,
// magnified so the largest is ~40 px long. Written by calibrate's report
// (cross_validation.png) and by omnical diff.
#pragma once

#include <string>

#include "calib/projection_diff.h"

namespace omnical {

// PNG written atomically; throws InputError naming the path on failure. `title` names the
// two calibrations compared.
void WriteProjectionDiffFigure(const std::string& path, const ProjectionDiff& diff, int width_px, int height_px,
                               const std::string& title);

}  // namespace omnical

// The figures of the design jobs (model/design): PNG plots and the dimensioned profile
// drawing (SVG + PNG), written into an output directory. Each throws InputError naming
// the path when a file cannot be written.
#pragma once

#include <string>

#include "model/design/design_fit_job.h"
#include "model/design/design_ode_job.h"

namespace omnical {

// design ode: law_ratio.png (the law ratio per distance, seed Figs. 10 and 14), profile.png
// (the profile and the ray diagram, Fig. 8), profile_drawing.svg / .png.
void WriteOdeDesignFigures(const DesignOdeResult& result, const std::string& dir);

// design fit: profile_drawing.svg / .png, characteristic.png (h vs Omega, seed Fig. 5, and
// the departure from the law, for the design and the compared sensor).
void WriteFitDesignFigures(const DesignFitResult& result, const std::string& dir);

}  // namespace omnical

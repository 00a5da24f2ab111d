// Whether a pinhole's tangential distortion (p1, p2: a decentred lens element,
// model/lenses.h) is fitted. Held by default with a guess (chosen here without one): the
// image shift it makes across the field trades with the mirror's decenter and the
// principal point, so on a sensor without a decentred lens it only fits noise (and a
// typical small decentring, p ~ 1e-3, is absorbed to within the corners' noise:
// docs/calibrate.md, "A decentred lens"). Chosen here by
// held-out folds (calib/fold_scores.h): fitted only where that predicts views the fit did
// not see better by more than kTangentialScoreTolerance (the knots' and the lens's
// parsimony rule), as the issue's "small non-symmetric term, kept only if
// cross-validation says so" asks.
#pragma once

#include <string>
#include <vector>

namespace omnical {

// CalibrationOptions::tangential: "" or kTangentialOff (held), kTangentialOn (fitted) or
// kChooseTangential.
inline constexpr const char* kTangentialOff = "off";
inline constexpr const char* kTangentialOn = "on";
inline constexpr const char* kChooseTangential = "auto";
// The candidates, the simpler first: p1, p2 held at the start's values, or fitted.
inline const std::vector<std::string> kTangentialCandidates = {"held", "fitted"};
constexpr double kTangentialScoreTolerance = 0.01;

}  // namespace omnical

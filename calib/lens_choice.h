// Which lens an unknown mirror is seen through, chosen by how well each predicts views it
// was not fitted to (calib/fold_scores.h): a telecentric lens or a perspective camera in
// front of the mirror. Through a free mirror shape the two fit a set's own corners about
// equally well (the shape bends for the difference: on the real dev set 0.3487 against
// 0.3498 px); where the lens is perspective, the orthographic model's non-centrality is
// wrong, and views it did not see show it.
#pragma once

#include <string>
#include <vector>

#include "calib/fold_scores.h"

namespace omnical {

// CalibrationOptions::lens: choose here.
inline constexpr const char* kChooseLens = "auto";
// The simplest first: the orthographic lens fits its principal point (its scale held), a
// pinhole also its focal lengths (k1, k2 held with a free shape); the pinhole is kept only
// where it predicts better by more than kLensScoreTolerance (the knots' parsimony rule,
// calib/knot_choice.h).
inline const std::vector<std::string> kLensCandidates = {"orthographic", "pinhole"};
constexpr double kLensScoreTolerance = 0.01;

// Calibrate scores kLensCandidates with ChooseByHeldOutFolds, each started from the rim
// circle through its lens (none, scored NaN, where some view had no starting pose through
// it). Where neither lens could be fitted to every fold (a held-out view posed, a valid
// sensor fitted) the first is kept, with the warning lens_not_chosen.

}  // namespace omnical

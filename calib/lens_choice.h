// Which lens an unknown mirror is seen through, chosen by how well each predicts views it
// was not fitted to (calib/fold_scores.h): a telecentric lens or a perspective camera in
// front of the mirror. Through a free mirror shape the two fit a set's own corners about
// equally well (the shape bends for the difference: on the real dev set 0.3487 against
// 0.3498 px); where the lens is perspective, the orthographic model's non-centrality is
// wrong, and views it did not see show it.
#pragma once

#include <optional>
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

struct LensChoice {
  std::vector<std::string> candidates;
  std::vector<double> held_out_rms_px;  // per candidate, NaN when it failed (a fold, or a view's start pose)
  int held_out_corners = 0;
  int folds = 0;
  std::string chosen;
};

// One candidate per kLensCandidates, in that order, each started from the rim circle
// through its lens; none where some view had no starting pose through it (scored NaN).
// Where neither lens could be fitted to every fold, `chosen` is the first (calibrate
// keeps its default start and warns lens_not_chosen). Throws InputError naming `lens`
// with fewer than 4 views.
LensChoice ChooseLens(const std::vector<std::optional<FoldCandidate>>& candidates, const CalibrationTarget& target,
                      const DetectionSet& views, int threads, const ProgressCallback& progress);

}  // namespace omnical

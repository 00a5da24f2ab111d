#include "calib/lens_choice.h"

#include <cmath>

namespace omnical {

LensChoice ChooseLens(const std::vector<std::optional<FoldCandidate>>& candidates, const CalibrationTarget& target,
                      const DetectionSet& views, int threads, const ProgressCallback& progress) {
  LensChoice choice;
  choice.candidates = kLensCandidates;
  std::vector<FoldCandidate> posed;
  for (const std::optional<FoldCandidate>& candidate : candidates)
    if (candidate) posed.push_back(*candidate);
  const FoldScores scores = ScoreByHeldOutFolds(posed, target, views, threads, "lens", "lens", progress);
  choice.folds = scores.folds;
  choice.held_out_corners = scores.held_out_corners;
  size_t next = 0;
  for (const std::optional<FoldCandidate>& candidate : candidates)
    choice.held_out_rms_px.push_back(candidate ? scores.held_out_rms_px[next++] : NAN);
  const int preferred =
      PreferredCandidate(choice.held_out_rms_px, std::vector<bool>(candidates.size(), false), kLensScoreTolerance);
  // Neither scored: the default start is kept (calibrate warns).
  choice.chosen = choice.candidates[preferred < 0 ? 0 : preferred];
  return choice;
}

}  // namespace omnical

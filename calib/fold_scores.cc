#include "calib/fold_scores.h"

#include <algorithm>
#include <cmath>

#include "calib/cross_validation.h"
#include "model/input_error.h"
#include "model/parallel_rows.h"

namespace omnical {

FoldScores ScoreByHeldOutFolds(const std::vector<FoldCandidate>& candidates, const CalibrationTarget& target,
                               const DetectionSet& views, int threads, const std::string& stage,
                               const std::string& field, const ProgressCallback& progress) {
  const int count = static_cast<int>(views.images.size());
  if (count < kMinViewsForFolds)
    throw InputError(field + ": choosing by held-out folds needs >= " + std::to_string(kMinViewsForFolds) +
                     " usable views (held-out folds leave >= 3 to fit); " + std::to_string(count) + " given");
  FoldScores result;
  result.folds = std::min(5, count);
  const int folds = result.folds, jobs = static_cast<int>(candidates.size()) * folds;
  ProgressReporter reporter(progress, stage, jobs);
  struct FoldScore {
    bool failed = false;
    double square = 0.0;
    int corners = 0;
  };
  std::vector<FoldScore> scores(jobs);
  ParallelRows(jobs, std::max(1, threads), [&](int reversed) {
    const int job = jobs - 1 - reversed;
    if (reporter.cancelled()) return;
    const FoldCandidate& candidate = candidates[job / folds];
    FitOptions options = candidate.options;
    options.compute_covariance = false;
    options.progress = nullptr;
    options.threads = 1;
    // Callbacks a caller gave the solver would be called from several fits at once.
    options.solver.callbacks.clear();
    const int fold = job % folds;
    DetectionSet training = views, held = views;
    training.images.clear(), held.images.clear();
    std::vector<TargetPose> poses;
    for (int v = 0; v < count; ++v) {
      if (v % folds == fold) {
        held.images.push_back(views.images[v]);
      } else {
        training.images.push_back(views.images[v]);
        poses.push_back(candidate.initial_poses[v]);
      }
    }
    FoldScore& score = scores[job];
    const FitResult fit = FitSensor(candidate.start, target, training, poses, options);
    // A fit that is no valid sensor fails too: calibrate could not write it. An ideal
    // paraboloid through a free pinhole on the near renders folded its k1, k2 in 4 of 5
    // folds, scored 3.58 px and was chosen, and its full fit's sensor.yaml did not load.
    if (fit.sensor && ValidateSensorModel(fit.sensor->model()).empty()) {
      if (fit.board_warp) options.board_warp = fit.board_warp->warp;
      const HeldOutViews held_out = EvaluateHeldOutViews(*fit.sensor, target, held, options);
      // A view whose pose cannot be fitted through this sensor, or a corner of it with no
      // residual, counts against the candidate as failing: its corners are not in the
      // score, so a score without them would flatter, and the candidates are compared on
      // the same corners.
      score.failed = !held_out.not_evaluated.empty() || !(held_out.corners > 0) || held_out.unscored_corners > 0;
      score.square = held_out.rms_px * held_out.rms_px * held_out.corners;
      score.corners = held_out.corners;
    } else {
      score.failed = true;
    }
    reporter.Advance();
  });
  reporter.ThrowIfCancelled();
  for (size_t k = 0; k < candidates.size(); ++k) {
    double square = 0.0;
    int corners = 0;
    bool failed = false;
    for (int fold = 0; fold < folds; ++fold) {
      const FoldScore& score = scores[k * folds + fold];
      failed |= score.failed;
      square += score.square;
      corners += score.corners;
    }
    result.held_out_rms_px.push_back(failed ? NAN : std::sqrt(square / corners));
    if (!failed) result.held_out_corners = corners;
  }
  return result;
}

int PreferredCandidate(const std::vector<double>& held_out_rms_px, const std::vector<bool>& excluded,
                       double tolerance) {
  double best = HUGE_VAL;
  for (size_t k = 0; k < held_out_rms_px.size(); ++k)
    if (!excluded[k] && std::isfinite(held_out_rms_px[k])) best = std::min(best, held_out_rms_px[k]);
  for (size_t k = 0; k < held_out_rms_px.size(); ++k)
    if (!excluded[k] && held_out_rms_px[k] <= best * (1.0 + tolerance)) return static_cast<int>(k);
  return -1;
}

bool NamedChoice::AnyScored() const {
  return std::any_of(held_out_rms_px.begin(), held_out_rms_px.end(), [](double rms) { return std::isfinite(rms); });
}

std::optional<KnownScore> KnownScoreOf(const NamedChoice& choice, const std::string& name) {
  const auto found = std::find(choice.candidates.begin(), choice.candidates.end(), name);
  const size_t index = found - choice.candidates.begin();
  if (found == choice.candidates.end() || index >= choice.held_out_rms_px.size()) return std::nullopt;
  return KnownScore{choice.held_out_rms_px[index], choice.held_out_corners};
}

NamedChoice ChooseByHeldOutFolds(const std::vector<std::string>& names,
                                 const std::vector<std::optional<FoldCandidate>>& candidates, double tolerance,
                                 const CalibrationTarget& target, const DetectionSet& views, int threads,
                                 const std::string& field, const ProgressCallback& progress,
                                 const std::vector<std::optional<KnownScore>>& known) {
  NamedChoice choice;
  choice.candidates = names;
  const auto known_at = [&](size_t k) { return k < known.size() ? known[k] : std::nullopt; };
  std::vector<FoldCandidate> fitted;
  for (size_t k = 0; k < candidates.size(); ++k)
    if (candidates[k] && !known_at(k)) fitted.push_back(*candidates[k]);
  const FoldScores scores = ScoreByHeldOutFolds(fitted, target, views, threads, field, field, progress);
  choice.folds = scores.folds;
  choice.held_out_corners = scores.held_out_corners;
  size_t next = 0;
  for (size_t k = 0; k < candidates.size(); ++k) {
    if (const std::optional<KnownScore> score = known_at(k)) {
      choice.held_out_rms_px.push_back(score->held_out_rms_px);
      if (std::isfinite(score->held_out_rms_px)) choice.held_out_corners = score->held_out_corners;
    } else {
      choice.held_out_rms_px.push_back(candidates[k] ? scores.held_out_rms_px[next++] : NAN);
    }
  }
  const int preferred =
      PreferredCandidate(choice.held_out_rms_px, std::vector<bool>(candidates.size(), false), tolerance);
  choice.chosen = choice.candidates[preferred < 0 ? 0 : preferred];
  return choice;
}

}  // namespace omnical

// How well each of several candidate models predicts views it was not fitted to: K-fold
// over the views, fold f holding out the views at positions f, f + K, ... (interleaved,
// as the two halves are: a hand-held set drifts); each candidate is calibrated on the
// rest and the held-out views' poses fitted with its sensor held (EvaluateHeldOutViews).
// The score is the RMS over every held-out corner of every fold, per corner
// sqrt(mean |e|^2). Used to choose a spline's knot count (calib/knot_choice.h), the lens
// and the mirror family of an unknown mirror (calib/lens_choice.h, calib/profile_choice.h)
// and whether a pinhole's tangential terms are fitted (calib/tangential_choice.h), never
// by training RMS, which only falls as parameters are added.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "calib/bundle_fit.h"
#include "calib/detections.h"
#include "calib/target.h"
#include "model/progress.h"
#include "model/sensor.h"

namespace omnical {

struct FoldCandidate {
  Sensor start;
  FitOptions options;                     // its fit's (no covariance is computed here)
  std::vector<TargetPose> initial_poses;  // per view
};

struct FoldScores {
  std::vector<double> held_out_rms_px;  // per candidate, NaN when a fold failed to fit (or to a valid sensor)
  int held_out_corners = 0;             // per candidate (the same corners for all)
  int folds = 0;
};

// The fewest usable views held-out folds can score: each fold leaves >= 3 to fit.
constexpr int kMinViewsForFolds = 4;

// Five folds where the views allow (each training set keeps 4/5 of them, close to the
// full fit the choice is for). The candidates' fold fits share `threads`, one fit per
// thread (a fit's result is the same for any thread count, so the scores are too); the
// last candidates' first (list the slowest last). Progress as stage `stage`. Throws
// InputError "field: ..." with fewer than kMinViewsForFolds views.
FoldScores ScoreByHeldOutFolds(const std::vector<FoldCandidate>& candidates, const CalibrationTarget& target,
                               const DetectionSet& views, int threads, const std::string& stage,
                               const std::string& field, const ProgressCallback& progress);

// The index of the first candidate not excluded whose score is within `tolerance` of the
// lowest of them (list the simplest first); -1 when none has a score.
int PreferredCandidate(const std::vector<double>& held_out_rms_px, const std::vector<bool>& excluded, double tolerance);

// A choice among named candidates by their held-out scores (the lens; the tangential terms).
struct NamedChoice {
  std::vector<std::string> candidates;
  std::vector<double> held_out_rms_px;  // per candidate, NaN when it failed (a fold, or a view's start pose)
  int held_out_corners = 0;
  int folds = 0;
  std::string chosen;  // the first candidate where none scored

  bool AnyScored() const;
};

// A score measured before on the same views and folds, reused instead of refitting.
struct KnownScore {
  double held_out_rms_px = 0.0;
  int held_out_corners = 0;
};

// The score `choice` gave the candidate `name` (NaN where it failed), to pass on as known
// where the same candidate is scored again on the same views; nothing where it has none.
std::optional<KnownScore> KnownScoreOf(const NamedChoice& choice, const std::string& name);

// The candidates given (one per name, the simplest first; an absent one scores NaN, one
// with a `known` score takes it unfitted) scored by ScoreByHeldOutFolds, and the preferred
// one within `tolerance` chosen.
NamedChoice ChooseByHeldOutFolds(const std::vector<std::string>& names,
                                 const std::vector<std::optional<FoldCandidate>>& candidates, double tolerance,
                                 const CalibrationTarget& target, const DetectionSet& views, int threads,
                                 const std::string& field, const ProgressCallback& progress,
                                 const std::vector<std::optional<KnownScore>>& known = {});

}  // namespace omnical

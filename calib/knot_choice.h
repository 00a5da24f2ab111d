// How many knots a spline mirror (model/spline_profile.h) gets, chosen by how well each
// count predicts views it was not fitted to, never by training RMS (which only falls as
// knots are added). K-fold over the views: fold f holds out the views at positions
// f, f + K, ... (interleaved, as the two halves are: a hand-held set drifts), the rest
// are calibrated with each candidate count, and the held-out views' poses are fitted with
// that sensor held (EvaluateHeldOutViews). The score is the RMS over every held-out
// corner of every fold, per corner sqrt(mean |e|^2).
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "calib/bundle_fit.h"
#include "calib/detections.h"
#include "calib/target.h"
#include "model/progress.h"
#include "model/sensor.h"

namespace omnical {

// CalibrationOptions::knots: choose the count here.
constexpr int kChooseKnots = -1;
// The counts tried: 0 stands for no spline (the base family: whether to use the spline at
// all is part of the choice), then from the fewest knots the spline allows to its most.
inline const std::vector<int> kKnotCandidates = {0, 4, 6, 8, 12, 16};
// Parsimony: the fewest knots (no spline first) whose score is within this fraction of the lowest. Below
// it the folds' scores do not separate the counts (on the real Mei set 6 and 12 knots
// differ by 1 % in training RMS and by less than the fold-to-fold spread held out).
constexpr double kKnotScoreTolerance = 0.01;

// "auto" -> kChooseKnots, else the count (range-checked by CalibrationOptions::Check);
// InputError "field: ..." for anything else.
int ParseKnotCount(const std::string& text, const std::string& field);

struct KnotChoice {
  std::string base_profile;  // candidate 0: the mirror family without a spline
  std::vector<int> candidates;
  std::vector<double> held_out_rms_px;  // per candidate, NaN when a fold failed to fit (or to a valid mirror)
  int held_out_corners = 0;             // per candidate (the same corners for all)
  int folds = 0;
  // The count the sensor was fitted with: PreferredKnotCount's among every candidate, or,
  // where calibrate's full fit with that count was no valid mirror, its pick among the
  // counts not yet tried (FitValidKnotCount).
  int chosen = 0;
};

// The index of the parsimonious count among the candidates not excluded: the fewest knots
// (no spline first) whose held-out RMS is within kKnotScoreTolerance of the lowest of
// them; -1 when none has a score.
int PreferredKnotCount(const KnotChoice& choice, const std::vector<bool>& excluded);

// The full set fitted with one count: FitSensor's result and the sensor it started from.
struct KnotCountFit {
  FitResult fit;
  Sensor start;
};

// What calibrate fits after the folds: the full set with the preferred count. The folds
// score how well a count predicts; the full fit with it may still bend the mirror more
// than a mirror can (z'' <= 0 where few corners reach, by the rim), and its sensor.yaml
// would not load (ValidateSensorModel). Then PreferredKnotCount among the counts not yet
// tried, until a full fit is a valid mirror.
struct ValidKnotFit {
  // The valid fit; if none, the first count that fitted at all (invalid); if none
  // fitted, empty and `failed` holds the first failure's result (its solver report).
  std::optional<KnotCountFit> fitted;
  std::optional<FitResult> failed;
  int knots = 0;  // fitted's count; the folds' choice when nothing fitted
  bool valid = false;
  // Why the count fitted is not the folds' choice, one line ("the full set fitted with 12
  // knots (no valid mirror); 8 knots, the folds' next choice, fitted instead"); empty
  // when it is.
  std::string replaced;
};

// fit_count(knots): the full set's fit with that candidate count (0: the base family,
// named base_profile in `replaced`).
ValidKnotFit FitValidKnotCount(const KnotChoice& choice, const std::string& base_profile,
                               const std::function<KnotCountFit(int knots)>& fit_count);

// The fit options for a candidate of another shape (knot count or family): the design
// values the priors are centred on keep every parameter the candidate shares with the
// guess and take the candidate's own values for its knots and for what the guess lacks.
FitOptions WithShapeOf(FitOptions options, const Sensor& candidate);

// start: the starting sensor, any family (converted to each candidate by its sag);
// base_profile: candidate 0's family (a family the fit can shape, not the spline);
// views/initial_poses: the views to fit (>= 4) and their starting poses; options: the
// full fit's (no covariance is computed here); the candidates' fold fits share
// options.threads, one fit per thread. Throws InputError naming `knots` when
// there are too few views or no count could be fitted.
KnotChoice ChooseKnots(const Sensor& start, const std::string& base_profile, const CalibrationTarget& target,
                       const DetectionSet& views,
                       const std::vector<TargetPose>& initial_poses, FitOptions options,
                       const ProgressCallback& progress = nullptr);

}  // namespace omnical

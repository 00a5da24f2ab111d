#include "calib/knot_choice.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <map>
#include <vector>

#include "calib/cross_validation.h"
#include "calib/initial_sensor.h"
#include "model/input_error.h"
#include "model/parallel_rows.h"
#include "model/progress.h"
#include "model/sensor.h"

namespace omnical {

int ParseKnotCount(const std::string& text, const std::string& field) {
  if (text == "auto") return kChooseKnots;
  size_t used = 0;
  int count = 0;
  try {
    count = std::stoi(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || count < 1)
    throw InputError(field + ": expected a knot count (4..16) or 'auto', got '" + text + "'");
  return count;
}

FitOptions WithShapeOf(FitOptions options, const Sensor& candidate) {
  if (options.design.empty()) return options;  // no priors to centre
  std::map<std::string, double> design;
  for (const ParameterEstimate& p : SensorParameters(candidate)) {
    const auto found = options.design.find(p.name);
    const bool knot = p.name.rfind("knot", 0) == 0;
    design[p.name] = knot || found == options.design.end() ? p.value : found->second;
  }
  options.design = std::move(design);
  return options;
}

int PreferredKnotCount(const KnotChoice& choice, const std::vector<bool>& excluded) {
  double best = HUGE_VAL;
  for (size_t k = 0; k < choice.candidates.size(); ++k)
    if (!excluded[k] && std::isfinite(choice.held_out_rms_px[k])) best = std::min(best, choice.held_out_rms_px[k]);
  for (size_t k = 0; k < choice.candidates.size(); ++k)
    if (!excluded[k] && choice.held_out_rms_px[k] <= best * (1.0 + kKnotScoreTolerance)) return static_cast<int>(k);
  return -1;
}

ValidKnotFit FitValidKnotCount(const KnotChoice& choice, const std::string& base_profile,
                               const std::function<KnotCountFit(int knots)>& fit_count) {
  const auto name = [&](int knots) { return knots > 0 ? std::to_string(knots) + " knots" : "the " + base_profile + " mirror"; };
  ValidKnotFit result;
  result.knots = choice.chosen;
  std::vector<bool> tried(choice.candidates.size(), false);
  std::string rejected;
  for (int k = PreferredKnotCount(choice, tried); k >= 0 && !result.valid; k = PreferredKnotCount(choice, tried)) {
    tried[k] = true;
    const int knots = choice.candidates[k];
    KnotCountFit candidate = fit_count(knots);
    const bool fitted = candidate.fit.sensor.has_value();
    const bool valid = fitted && ValidateSensorModel(candidate.fit.sensor->model()).empty();
    if (valid || (fitted && !result.fitted)) {
      result.fitted = std::move(candidate);
      result.knots = knots;
      result.valid = valid;
    } else if (!fitted && !result.failed) {
      result.failed = std::move(candidate.fit);
    }
    if (!valid) {
      const std::string label = knots > 0 ? std::to_string(knots) + " knots" : base_profile;
      rejected += (rejected.empty() ? "" : ", ") + label + (fitted ? " (no valid mirror)" : " (no fit)");
    }
  }
  if (result.fitted && result.knots != choice.chosen)
    result.replaced = "the full set fitted with " + rejected + "; " + name(result.knots) +
                      ", the folds' next choice, fitted instead" + (result.valid ? "" : " (no valid mirror either)");
  return result;
}

KnotChoice ChooseKnots(const Sensor& start, const std::string& base_profile, const CalibrationTarget& target,
                       const DetectionSet& views,
                       const std::vector<TargetPose>& initial_poses, FitOptions options, const ProgressCallback& progress) {
  if (base_profile == "spline") throw InputError("knots: the base family to compare the spline with cannot be a spline");
  const int count = static_cast<int>(views.images.size());
  if (count < 4)
    throw InputError("knots: choosing the count needs >= 4 usable views (held-out folds leave >= 3 to fit); " +
                     std::to_string(count) + " given");
  KnotChoice choice;
  choice.base_profile = base_profile;
  choice.candidates = kKnotCandidates;
  // Five folds where the views allow: each training set keeps 4/5 of the views, close to
  // the full fit the choice is for.
  choice.folds = std::min(5, count);
  options.compute_covariance = false;
  options.progress = nullptr;
  const int folds = choice.folds, jobs = static_cast<int>(choice.candidates.size()) * folds;
  ProgressReporter reporter(progress, "knots", jobs);
  std::vector<Sensor> candidates;
  for (int knots : choice.candidates)
    candidates.push_back(knots > 0 ? ConvertProfile(start, "spline", knots) : ConvertProfile(start, base_profile));
  // Every (count, fold) fit is independent: they share the threads, one fit each (a fit's
  // result is the same for any thread count, so the choice is too).
  struct FoldScore {
    bool failed = false;
    double square = 0.0;
    int corners = 0;
  };
  std::vector<FoldScore> scores(jobs);
  const int workers = std::max(1, options.threads);
  options.threads = 1;
  // Callbacks a caller gave the solver would be called from several fits at once.
  options.solver.callbacks.clear();
  // The most knots (the slowest fits) first, so no long fit starts last.
  ParallelRows(jobs, workers, [&](int reversed) {
    const int job = jobs - 1 - reversed;
    if (reporter.cancelled()) return;
    const Sensor& candidate = candidates[job / folds];
    const int fold = job % folds;
    DetectionSet training = views, held = views;
    training.images.clear(), held.images.clear();
    std::vector<TargetPose> poses;
    for (int v = 0; v < count; ++v) {
      if (v % folds == fold) {
        held.images.push_back(views.images[v]);
      } else {
        training.images.push_back(views.images[v]);
        poses.push_back(initial_poses[v]);
      }
    }
    FoldScore& score = scores[job];
    const FitResult fit = FitSensor(candidate, target, training, poses, WithShapeOf(options, candidate));
    if (fit.sensor) {
      FitOptions held_options = WithShapeOf(options, candidate);
      if (fit.board_warp) held_options.board_warp = fit.board_warp->warp;
      const HeldOutViews result = EvaluateHeldOutViews(*fit.sensor, target, held, held_options);
      // A view whose pose cannot be fitted through this sensor counts against the count
      // as failing: its corners are not in the score, so a score without them would flatter.
      score.failed = !result.not_evaluated.empty() || !(result.corners > 0);
      score.square = result.rms_px * result.rms_px * result.corners;
      score.corners = result.corners;
    } else {
      score.failed = true;
    }
    reporter.Advance();
  });
  reporter.ThrowIfCancelled();
  for (size_t k = 0; k < choice.candidates.size(); ++k) {
    double square = 0.0;
    int corners = 0;
    bool failed = false;
    for (int fold = 0; fold < folds; ++fold) {
      const FoldScore& score = scores[k * folds + fold];
      failed |= score.failed;
      square += score.square;
      corners += score.corners;
    }
    choice.held_out_rms_px.push_back(failed ? NAN : std::sqrt(square / corners));
    if (!failed) choice.held_out_corners = corners;
  }
  const int preferred = PreferredKnotCount(choice, std::vector<bool>(choice.candidates.size(), false));
  if (preferred < 0) throw InputError("knots: no knot count could be fitted to every fold of the views");
  choice.chosen = choice.candidates[preferred];
  return choice;
}

}  // namespace omnical

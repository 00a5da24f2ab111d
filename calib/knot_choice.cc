#include "calib/knot_choice.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <map>
#include <vector>

#include "calib/fold_scores.h"
#include "calib/initial_sensor.h"
#include "model/input_error.h"
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
  return PreferredCandidate(choice.held_out_rms_px, excluded, kKnotScoreTolerance);
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
  KnotChoice choice;
  choice.base_profile = base_profile;
  choice.candidates = kKnotCandidates;
  // The most knots (the slowest fits) last: scored first, so no long fit starts last.
  std::vector<FoldCandidate> candidates;
  for (int knots : choice.candidates) {
    Sensor sensor = knots > 0 ? ConvertProfile(start, "spline", knots) : ConvertProfile(start, base_profile);
    FitOptions sensor_options = WithShapeOf(options, sensor);
    candidates.push_back({std::move(sensor), std::move(sensor_options), initial_poses});
  }
  const FoldScores scores = ScoreByHeldOutFolds(candidates, target, views, options.threads, "knots", "knots", progress);
  choice.held_out_rms_px = scores.held_out_rms_px;
  choice.held_out_corners = scores.held_out_corners;
  choice.folds = scores.folds;
  const int preferred = PreferredKnotCount(choice, std::vector<bool>(choice.candidates.size(), false));
  if (preferred < 0)
    throw InputError("knots: no knot count could be fitted to every fold of the views (each fold to a valid mirror)");
  choice.chosen = choice.candidates[preferred];
  return choice;
}

}  // namespace omnical

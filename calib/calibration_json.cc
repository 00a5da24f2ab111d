#include "calib/calibration_json.h"

#include <nlohmann/json.hpp>

#include <cmath>

#include "calib/fit_covariance.h"
#include "calib/predicted_error.h"
#include "model/io/atomic_write.h"
#include "model/input_error.h"
#include "model/io/json_file.h"

namespace omnical {
namespace {

using nlohmann::json;

const char* const kPredictedErrorDefinition =
    "per pixel of the observed field: sqrt(trace(J C J^T)), the RMS length of the 2-D error vector of a point at "
    "that distance from its reflection point, C the fit's covariance (poses marginalised), J after the rigid "
    "alignment fitted at aligned_at_mm (the boards' median distance) and applied at every distance, as omnical diff "
    "--align-at-mm compares; in_camera_frame_*: J of points held fixed in the camera's frame";

const char* const kHoldoutDefinition =
    "views kept out of the fit (spread evenly over the input), their poses fitted with the sensor held; rms_px over "
    "all their corners, per corner sqrt(mean |e|^2); compare with training_rms_px (the fitted views, all corners)";
const char* const kHoldoutFoldsDefinition =
    "every usable view held out once, views_per_fold at a time: per fold a calibration without its views (fitted "
    "without them, their corners refined in the later detection passes through fits without them; fold f of F keeps "
    "out the usable views f, f + F, ... in the input's order), their poses "
    "fitted with that sensor held; rms_px over every fold's held-out corners, training_rms_px over every fold's "
    "fitted corners, both all corners, per corner sqrt(mean |e|^2); the written sensor is the full set's fit";
const char* const kBoardWarpDefinition =
    "the board's out-of-plane shape z = x_mm (1 - u^2) + y_mm (1 - v^2) along its normal, u, v the corner's position "
    "scaled to [-1, 1] over the board's corners: the deflections at the centre relative to the edges (mm); with a "
    "fitted relief, each corner's own offset (id, offset_mm, std_mm) added to z";
const char* const kKnotChoiceDefinition =
    "the spline mirror's knot count chosen by held-out folds: the fitted views split into `folds` interleaved folds, "
    "each held out in turn while the rest are calibrated with every candidate count; candidate 0 is base_profile (no spline); held_out_rms_px over every "
    "held-out corner of every fold (poses fitted, sensor held), per corner sqrt(mean |e|^2); chosen: the fewest "
    "knots (0 first) within 1 % of the lowest, or, where the full set fitted with that count is no valid mirror, the "
    "same rule over the counts not yet tried (warning knot_count_replaced)";
const char* const kLensChoiceDefinition =
    "the lens an unknown mirror is seen through, chosen by held-out folds on the first detection pass's corners: the "
    "usable views split into `folds` interleaved folds, each held out in turn while the rest are calibrated from the "
    "rim circle through every candidate lens; held_out_rms_px over every held-out corner of every fold (poses fitted, "
    "sensor held), per corner sqrt(mean |e|^2), null where a fold failed (no fit, no valid sensor, or a held-out "
    "view or corner without a residual through the lens); "
    "chosen: the first candidate within 1 % of the lowest, the first where none scored (warning lens_not_chosen)";
const char* const kProfileChoiceDefinition =
    "the mirror family an unknown mirror is fitted as (polynomial: the 3-term even polynomial; even_asphere: a conic), "
    "chosen by held-out folds on the first detection pass's corners through the lens chosen: the usable views split "
    "into `folds` interleaved folds, each held out in turn while the rest are calibrated from the rim circle as every "
    "candidate family; held_out_rms_px over every held-out corner of every fold (poses fitted, sensor held), per "
    "corner sqrt(mean |e|^2), null where a fold failed (no fit, no valid sensor, or a held-out view or corner without "
    "a residual); chosen: the first candidate within 1 % of the lowest, the first where none scored";
const char* const kReliefChoiceDefinition =
    "whether the board's relief (each corner's own out-of-plane offset on top of the warp, board_warp.relief) is "
    "fitted (candidate warp+relief) or not (warp), chosen by held-out folds on the first detection pass's corners: "
    "the usable views split into `folds` interleaved folds, each held out in turn while the rest are calibrated both "
    "ways, the board's shape held for the held-out views; held_out_rms_px over every held-out corner of every fold "
    "(poses fitted, sensor held), per corner sqrt(mean |e|^2), null where a fold failed; chosen: the first candidate "
    "within 1 % of the lowest, the first where none scored";
const char* const kTangentialChoiceDefinition =
    "whether the pinhole's tangential distortion p1, p2 is fitted (candidate fitted) or held at the start's values "
    "(held), chosen by held-out folds on the first detection pass's corners: the usable views split into `folds` "
    "interleaved folds, each held out in turn while the rest are calibrated both ways; held_out_rms_px over every "
    "held-out corner of every fold (poses fitted, sensor held), per corner sqrt(mean |e|^2), null where a fold "
    "failed (no fit, no valid sensor, or a held-out corner without a residual); chosen: the first candidate within "
    "1 % of the lowest, the first where none scored";
const char* const kCrossValidationDefinition =
    "the usable views split into even and odd positions, each half calibrated alone; the points distance_mm along "
    "each observed field pixel's ray through half 1 (from its reflection point), moved by the rigid motion that "
    "best aligns them, projected through half 2; diff_*_px are lengths of the 2-D pixel differences; "
    "aligned_at_boards: the same with one rigid motion fitted at aligned_at_mm (the boards' median distance) and "
    "carried to distance_mm, as the predicted error";

json NumberOrNull(double value) { return std::isfinite(value) ? json(value) : json(nullptr); }
double NumberOrNan(const json& value) { return value.is_null() ? NAN : value.get<double>(); }

// What every choice by held-out folds records (KnotChoice, NamedChoice: calib/fold_scores.h).
template <typename Choice>
json FoldChoiceJson(const Choice& choice, const char* definition) {
  json out;
  out["candidates"] = choice.candidates;
  out["held_out_rms_px"] = json::array();
  for (double rms : choice.held_out_rms_px) out["held_out_rms_px"].push_back(NumberOrNull(rms));
  out["held_out_corners"] = choice.held_out_corners;
  out["folds"] = choice.folds;
  out["chosen"] = choice.chosen;
  out["definition"] = definition;
  return out;
}
template <typename Choice>
Choice FoldChoiceFromJson(const json& in, const std::string& name, const std::string& key) {
  Choice choice;
  choice.candidates = in.at("candidates").get<decltype(choice.candidates)>();
  for (const json& rms : in.at("held_out_rms_px")) choice.held_out_rms_px.push_back(NumberOrNan(rms));
  choice.held_out_corners = in.at("held_out_corners").get<int>();
  choice.folds = in.at("folds").get<int>();
  choice.chosen = in.at("chosen").get<decltype(choice.chosen)>();
  if (choice.held_out_rms_px.size() != choice.candidates.size())
    throw InputError(InputMessage(name, key + ".held_out_rms_px", "must have one value per candidate"));
  return choice;
}
json DistanceOrInfinity(double value, bool infinite) { return infinite ? json("infinity") : json(value); }
double ReadDistance(const json& value, double infinity) {
  return value.is_string() && value.get<std::string>() == "infinity" ? infinity : value.get<double>();
}
// Where an alignment was fitted: a distance, "infinity", or null (none).
json AlignedAtJson(double aligned_at_mm) {
  return std::isfinite(aligned_at_mm) ? DistanceOrInfinity(aligned_at_mm, aligned_at_mm >= kInfinityMm) : json(nullptr);
}
double ReadAlignedAt(const json& value) { return value.is_null() ? NAN : ReadDistance(value, kInfinityMm); }

// The summary of a projection difference (calibration.json's cross_validation, diff.json).
json DiffSummary(const ProjectionDiff& d) {
  return {{"distance_mm", DistanceOrInfinity(d.distance_mm, d.distance_mm >= kInfinityMm)},
          {"diff_rms_px", NumberOrNull(d.rms_px)},
          {"diff_median_px", NumberOrNull(d.median_px)},
          {"diff_max_px", NumberOrNull(d.max_px)},
          {"unaligned_rms_px", NumberOrNull(d.unaligned_rms_px)},
          {"grid_points", d.compared},
          {"aligned", d.aligned},
          {"aligned_at_mm", AlignedAtJson(d.aligned_at_mm)},
          {"moved_off_mirror", d.moved_off_mirror},
          {"rotation_deg", d.rotation_deg},
          {"translation_mm", {d.translation_mm.x(), d.translation_mm.y(), d.translation_mm.z()}}};
}

// DiffSummary's fields back (no per-pixel data).
ProjectionDiff ReadDiffSummary(const json& c) {
  ProjectionDiff diff;
  diff.distance_mm = ReadDistance(c.at("distance_mm"), kInfinityMm);
  diff.rms_px = NumberOrNan(c.at("diff_rms_px"));
  diff.median_px = NumberOrNan(c.at("diff_median_px"));
  diff.max_px = NumberOrNan(c.at("diff_max_px"));
  diff.unaligned_rms_px = NumberOrNan(c.at("unaligned_rms_px"));
  diff.compared = c.at("grid_points").get<int>();
  if (c.contains("moved_off_mirror")) diff.moved_off_mirror = c.at("moved_off_mirror").get<int>();
  diff.aligned = c.at("aligned").get<bool>();
  diff.rotation_deg = c.at("rotation_deg").get<double>();
  // Older files: an alignment was always fitted at the compared distance.
  diff.aligned_at_mm = c.contains("aligned_at_mm") ? ReadAlignedAt(c.at("aligned_at_mm"))
                       : diff.aligned              ? diff.distance_mm
                                                   : NAN;
  const json& t = c.at("translation_mm");
  diff.translation_mm = Eigen::Vector3d(t.at(0).get<double>(), t.at(1).get<double>(), t.at(2).get<double>());
  return diff;
}

json ToJson(const CalibrationRecord& r) {
  json j;
  j["rms_px"] = r.rms_px;
  j["rms_all_px"] = NumberOrNull(r.rms_all_px);
  j["converged"] = r.converged;
  j["outliers"] = r.outliers;
  j["dropped"] = r.dropped;
  j["unrefined_corners_left_out"] = r.unrefined_corners_left_out;
  j["observations"] = r.observations;
  j["solver_report"] = r.solver_report;
  j["fixed_blocks"] = r.fixed_blocks;
  j["robust_loss_px"] = r.robust_loss_px;
  j["covariance_ok"] = r.covariance_ok;
  j["start"] = r.start;
  j["detection_passes"] = r.detection_passes;
  if (r.rim_circle)
    j["rim_circle"] = {{"centre_px", {r.rim_circle->centre_px.x(), r.rim_circle->centre_px.y()}},
                       {"radius_px", r.rim_circle->radius_px},
                       {"inlier_fraction", r.rim_circle->inlier_fraction},
                       {"rms_px", r.rim_circle->rms_px}};
  for (const auto& [name, s] : r.leave_one_out) j["leave_one_out"][name] = {{"min", s.min}, {"max", s.max}, {"std", s.std}};
  if (const auto& w = r.board_warp) {
    j["board_warp"] = {{"x_mm", w->warp.x_mm}, {"y_mm", w->warp.y_mm}, {"std_x_mm", NumberOrNull(w->std_x_mm)},
                       {"std_y_mm", NumberOrNull(w->std_y_mm)}, {"definition", kBoardWarpDefinition}};
    if (!w->warp.relief_mm.empty()) {
      json relief = json::array();
      for (const auto& [id, offset_mm] : w->warp.relief_mm) {
        const auto std_mm = w->relief_std_mm.find(id);
        relief.push_back({{"id", id},
                          {"offset_mm", offset_mm},
                          {"std_mm", NumberOrNull(std_mm == w->relief_std_mm.end() ? NAN : std_mm->second)}});
      }
      j["board_warp"]["relief"] = relief;
    }
  }
  if (const auto& k = r.knot_choice) {
    json& out = j["knot_choice"] = FoldChoiceJson(*k, kKnotChoiceDefinition);
    out["base_profile"] = k->base_profile;
  }
  if (const auto& l = r.lens_choice) j["lens_choice"] = FoldChoiceJson(*l, kLensChoiceDefinition);
  if (const auto& p = r.profile_choice) j["profile_choice"] = FoldChoiceJson(*p, kProfileChoiceDefinition);
  if (const auto& t = r.tangential_choice) j["tangential_choice"] = FoldChoiceJson(*t, kTangentialChoiceDefinition);
  if (const auto& b = r.relief_choice) j["relief_choice"] = FoldChoiceJson(*b, kReliefChoiceDefinition);
  if (const auto& h = r.holdout) {
    json& out = j["holdout"];
    out["views"] = h->images;
    out["rms_px"] = NumberOrNull(h->rms_px);
    out["inlier_rms_px"] = NumberOrNull(h->inlier_rms_px);
    out["corners"] = h->corners;
    out["outliers"] = h->outliers;
    for (const auto& [image, rms] : h->per_view_rms_px) out["per_view_rms_px"][image] = NumberOrNull(rms);
    for (const auto& [image, why] : h->not_evaluated) out["not_evaluated"][image] = why;
    out["training_rms_px"] = NumberOrNull(r.rms_all_px);
    out["training_inlier_rms_px"] = r.rms_px;
    out["definition"] = kHoldoutDefinition;
  }
  if (const auto& h = r.holdout_folds) {
    json& out = j["holdout_folds"];
    out["views_per_fold"] = h->views_per_fold;
    out["folds"] = json::array();
    for (const HeldOutFolds::Fold& fold : h->folds)
      out["folds"].push_back({{"views", fold.images},
                              {"rms_px", NumberOrNull(fold.rms_px)},
                              {"corners", fold.corners},
                              {"training_rms_px", NumberOrNull(fold.training_rms_px)},
                              {"training_corners", fold.training_corners}});
    for (const auto& [image, rms] : h->per_view_rms_px) out["per_view_rms_px"][image] = NumberOrNull(rms);
    out["rms_px"] = NumberOrNull(h->rms_px);
    out["corners"] = h->corners;
    out["training_rms_px"] = NumberOrNull(h->training_rms_px);
    out["training_corners"] = h->training_corners;
    out["definition"] = kHoldoutFoldsDefinition;
  }
  if (const auto& c = r.cross_validation) {
    json& out = j["cross_validation"];
    out = DiffSummary(c->diff);
    out["halves"] = c->halves;
    out["half_rms_px"] = {NumberOrNull(c->half_rms_px[0]), NumberOrNull(c->half_rms_px[1])};
    if (c->diff_aligned_at_boards) out["aligned_at_boards"] = DiffSummary(*c->diff_aligned_at_boards);
    out["definition"] = kCrossValidationDefinition;
  }
  j["target_distance_mm"] = {{"nearest", r.nearest_target_mm}, {"farthest", r.farthest_target_mm}};
  for (const auto& [image, why] : r.views_left_out) j["views_left_out"][image] = why;
  for (const auto& [image, why] : r.views_skipped) j["views_skipped"][image] = why;
  j["outlier_threshold_px"] = r.outlier_threshold_px;
  for (const auto& [image, count] : r.per_view_outliers) j["per_view_outliers"][image] = count;
  j["sigma_px"] = r.sigma_px;
  j["tolerances"] = r.tolerances;
  j["rim_radius_mm"] = {{"guess", r.guess_rim_radius_mm}, {"fitted", r.fitted_rim_radius_mm}};
  if (r.covariance_ok) {
    j["covariance"]["names"] = r.covariance_names;
    for (int row = 0; row < r.covariance.rows(); ++row) {
      std::vector<double> values(r.covariance.cols());
      for (int col = 0; col < r.covariance.cols(); ++col) values[col] = r.covariance(row, col);
      j["covariance"]["matrix"].push_back(values);
    }
    // The same as correlations (unit diagonal), for people reading the file.
    const Eigen::MatrixXd correlation = CorrelationOf(r.covariance);
    j["correlation"]["names"] = r.covariance_names;
    for (int row = 0; row < correlation.rows(); ++row) {
      std::vector<double> values(correlation.cols());
      for (int col = 0; col < correlation.cols(); ++col) values[col] = correlation(row, col);
      j["correlation"]["matrix"].push_back(values);
    }
    if (std::isfinite(r.scale_block_condition)) j["scale_block_condition"] = r.scale_block_condition;
  }
  for (const auto& p : r.predicted_error) {
    const bool infinite = p.distance_mm >= kInfinityMm;
    j["predicted_error"].push_back({{"distance_mm", DistanceOrInfinity(p.distance_mm, infinite)},
                                    {"n_rim_radii", DistanceOrInfinity(p.n_rim_radii, infinite)},
                                    {"median_px", NumberOrNull(p.median_px)},
                                    {"max_px", NumberOrNull(p.max_px)},
                                    {"field_pixels", p.field_pixels},
                                    {"unpredicted_pixels", p.unpredicted_pixels},
                                    {"in_camera_frame_median_px", NumberOrNull(p.in_camera_frame_median_px)},
                                    {"in_camera_frame_max_px", NumberOrNull(p.in_camera_frame_max_px)},
                                    {"aligned_at_mm", AlignedAtJson(p.aligned_at_mm)}});
  }
  if (r.covariance_ok) j["predicted_error_definition"] = kPredictedErrorDefinition;
  j["warnings"] = r.warnings;
  for (const auto& [image, rms] : r.per_view_rms_px) j["per_view_rms_px"][image] = rms;
  for (const auto& [image, weight] : r.per_view_weight) j["per_view_weight"][image] = NumberOrNull(weight);
  for (const ParameterEstimate& p : r.parameters)
    j["parameters"][p.name] = {{"value", p.value}, {"std", NumberOrNull(p.std)}, {"fixed", p.fixed}};
  for (const auto& [image, pose] : r.poses) {
    const Eigen::Quaterniond& q = pose.camera_from_target_rotation;
    const Eigen::Vector3d& t = pose.camera_from_target_translation_mm;
    j["poses"][image] = {{"camera_from_target_quaternion_wxyz", {q.w(), q.x(), q.y(), q.z()}},
                         {"camera_from_target_translation_mm", {t.x(), t.y(), t.z()}}};
  }
  return j;
}

CalibrationRecord FromJson(const json& j, const std::string& name) {
  CalibrationRecord r;
  std::string field;
  // Each field is read under its name so a type error names it.
  auto at = [&](const char* key) -> const json& {
    field = key;
    return j.at(key);
  };
  try {
    if (!j.is_object()) throw InputError(InputMessage(name, "", "is not a JSON object"));
    r.rms_px = at("rms_px").get<double>();
    r.converged = at("converged").get<bool>();
    r.outliers = at("outliers").get<int>();
    r.dropped = at("dropped").get<int>();
    r.unrefined_corners_left_out = at("unrefined_corners_left_out").get<int>();
    r.observations = at("observations").get<int>();
    r.solver_report = at("solver_report").get<std::string>();
    r.fixed_blocks = at("fixed_blocks").get<std::set<std::string>>();
    r.robust_loss_px = at("robust_loss_px").get<double>();
    r.covariance_ok = at("covariance_ok").get<bool>();
    r.start = at("start").get<std::string>();
    r.detection_passes = at("detection_passes").get<int>();
    if (j.contains("rim_circle")) {
      const json& c = at("rim_circle");
      r.rim_circle = CalibrationRecord::RimCircleRecord{
          Eigen::Vector2d(c.at("centre_px").at(0).get<double>(), c.at("centre_px").at(1).get<double>()),
          c.at("radius_px").get<double>(), c.at("inlier_fraction").get<double>(), c.at("rms_px").get<double>()};
    }
    if (j.contains("leave_one_out"))
      for (const auto& [parameter, s] : at("leave_one_out").items())
        r.leave_one_out[parameter] = {s.at("min").get<double>(), s.at("max").get<double>(), s.at("std").get<double>()};
    if (j.contains("rms_all_px")) r.rms_all_px = NumberOrNan(at("rms_all_px"));
    if (j.contains("board_warp")) {
      const json& w = at("board_warp");
      BoardWarpEstimate estimate;
      estimate.warp.x_mm = w.at("x_mm").get<double>();
      estimate.warp.y_mm = w.at("y_mm").get<double>();
      estimate.std_x_mm = NumberOrNan(w.at("std_x_mm"));
      estimate.std_y_mm = NumberOrNan(w.at("std_y_mm"));
      if (w.contains("relief"))
        for (const json& corner : w.at("relief")) {
          const int id = corner.at("id").get<int>();
          estimate.warp.relief_mm[id] = corner.at("offset_mm").get<double>();
          estimate.relief_std_mm[id] = NumberOrNan(corner.at("std_mm"));
        }
      r.board_warp = estimate;
    }
    if (j.contains("knot_choice")) {
      const json& k = at("knot_choice");
      r.knot_choice = FoldChoiceFromJson<KnotChoice>(k, name, "knot_choice");
      r.knot_choice->base_profile = k.at("base_profile").get<std::string>();
    }
    if (j.contains("lens_choice")) r.lens_choice = FoldChoiceFromJson<NamedChoice>(at("lens_choice"), name, "lens_choice");
    if (j.contains("profile_choice"))
      r.profile_choice = FoldChoiceFromJson<NamedChoice>(at("profile_choice"), name, "profile_choice");
    if (j.contains("tangential_choice"))
      r.tangential_choice = FoldChoiceFromJson<NamedChoice>(at("tangential_choice"), name, "tangential_choice");
    if (j.contains("relief_choice"))
      r.relief_choice = FoldChoiceFromJson<NamedChoice>(at("relief_choice"), name, "relief_choice");
    if (j.contains("holdout")) {
      const json& h = at("holdout");
      HeldOutViews held;
      held.images = h.at("views").get<std::vector<std::string>>();
      held.rms_px = NumberOrNan(h.at("rms_px"));
      held.inlier_rms_px = NumberOrNan(h.at("inlier_rms_px"));
      held.corners = h.at("corners").get<int>();
      held.outliers = h.at("outliers").get<int>();
      if (h.contains("per_view_rms_px"))
        for (const auto& [image, rms] : h.at("per_view_rms_px").items()) held.per_view_rms_px[image] = NumberOrNan(rms);
      if (h.contains("not_evaluated")) held.not_evaluated = h.at("not_evaluated").get<std::map<std::string, std::string>>();
      r.holdout = held;
    }
    if (j.contains("holdout_folds")) {
      const json& h = at("holdout_folds");
      HeldOutFolds folds;
      folds.views_per_fold = h.at("views_per_fold").get<int>();
      for (const json& f : h.at("folds")) {
        HeldOutFolds::Fold fold;
        fold.images = f.at("views").get<std::vector<std::string>>();
        fold.rms_px = NumberOrNan(f.at("rms_px"));
        fold.corners = f.at("corners").get<int>();
        fold.training_rms_px = NumberOrNan(f.at("training_rms_px"));
        fold.training_corners = f.at("training_corners").get<int>();
        folds.folds.push_back(fold);
      }
      if (h.contains("per_view_rms_px"))
        for (const auto& [image, rms] : h.at("per_view_rms_px").items()) folds.per_view_rms_px[image] = NumberOrNan(rms);
      folds.rms_px = NumberOrNan(h.at("rms_px"));
      folds.corners = h.at("corners").get<int>();
      folds.training_rms_px = NumberOrNan(h.at("training_rms_px"));
      folds.training_corners = h.at("training_corners").get<int>();
      r.holdout_folds = folds;
    }
    if (j.contains("cross_validation")) {
      const json& c = at("cross_validation");
      CalibrationRecord::CrossValidationRecord cross;
      cross.halves = c.at("halves").get<std::array<std::vector<std::string>, 2>>();
      cross.half_rms_px = {NumberOrNan(c.at("half_rms_px").at(0)), NumberOrNan(c.at("half_rms_px").at(1))};
      cross.diff = ReadDiffSummary(c);
      if (c.contains("aligned_at_boards")) cross.diff_aligned_at_boards = ReadDiffSummary(c.at("aligned_at_boards"));
      r.cross_validation = cross;
    }
    const json& distance = at("target_distance_mm");
    r.nearest_target_mm = distance.at("nearest").is_null() ? HUGE_VAL : distance.at("nearest").get<double>();
    r.farthest_target_mm = distance.at("farthest").get<double>();
    if (j.contains("views_left_out")) r.views_left_out = at("views_left_out").get<std::map<std::string, std::string>>();
    if (j.contains("views_skipped")) r.views_skipped = at("views_skipped").get<std::map<std::string, std::string>>();
    r.outlier_threshold_px = at("outlier_threshold_px").get<double>();
    if (j.contains("per_view_outliers")) r.per_view_outliers = at("per_view_outliers").get<std::map<std::string, int>>();
    r.sigma_px = at("sigma_px").get<double>();
    if (!at("tolerances").is_null()) r.tolerances = at("tolerances").get<DesignTolerances>();
    r.guess_rim_radius_mm = at("rim_radius_mm").at("guess").get<double>();
    r.fitted_rim_radius_mm = j.at("rim_radius_mm").at("fitted").get<double>();
    if (j.contains("covariance")) {
      const json& c = at("covariance");
      r.covariance_names = c.at("names").get<std::vector<std::string>>();
      const int size = static_cast<int>(r.covariance_names.size());
      r.covariance.resize(size, size);
      for (int row = 0; row < size; ++row)
        for (int col = 0; col < size; ++col) r.covariance(row, col) = c.at("matrix").at(row).at(col).get<double>();
    }
    if (j.contains("scale_block_condition")) r.scale_block_condition = at("scale_block_condition").get<double>();
    if (j.contains("predicted_error"))
      for (const json& p : at("predicted_error")) {
        CalibrationRecord::PredictedErrorSummary summary{
            ReadDistance(p.at("distance_mm"), kInfinityMm), ReadDistance(p.at("n_rim_radii"), HUGE_VAL),
            NumberOrNan(p.at("median_px")),                 NumberOrNan(p.at("max_px")),
            p.at("field_pixels").get<int>(),                p.at("unpredicted_pixels").get<int>()};
        if (p.contains("in_camera_frame_max_px")) {
          summary.in_camera_frame_median_px = NumberOrNan(p.at("in_camera_frame_median_px"));
          summary.in_camera_frame_max_px = NumberOrNan(p.at("in_camera_frame_max_px"));
        } else {
          // Written before the prediction was aligned (2026-11-29): its figures were the
          // camera frame's, and the aligned ones are unknown.
          summary.in_camera_frame_median_px = summary.median_px;
          summary.in_camera_frame_max_px = summary.max_px;
          summary.median_px = summary.max_px = NAN;
        }
        if (p.contains("aligned_at_mm")) summary.aligned_at_mm = ReadAlignedAt(p.at("aligned_at_mm"));
        r.predicted_error.push_back(summary);
      }
    r.warnings = at("warnings").get<std::vector<std::string>>();
    if (j.contains("per_view_rms_px"))  // a view left out has no RMS: null
      for (const auto& [image, rms] : at("per_view_rms_px").items()) r.per_view_rms_px[image] = NumberOrNan(rms);
    if (j.contains("per_view_weight"))
      for (const auto& [image, weight] : at("per_view_weight").items()) r.per_view_weight[image] = NumberOrNan(weight);
    for (const auto& [parameter, p] : at("parameters").items())
      r.parameters.push_back({parameter, p.at("value").get<double>(), NumberOrNan(p.at("std")), p.at("fixed").get<bool>()});
    if (j.contains("poses"))
      for (const auto& [image, p] : at("poses").items()) {
        const json& q = p.at("camera_from_target_quaternion_wxyz");
        const json& t = p.at("camera_from_target_translation_mm");
        TargetPose pose;
        pose.camera_from_target_rotation =
            Eigen::Quaterniond(q.at(0).get<double>(), q.at(1).get<double>(), q.at(2).get<double>(), q.at(3).get<double>());
        pose.camera_from_target_translation_mm = Eigen::Vector3d(t.at(0).get<double>(), t.at(1).get<double>(), t.at(2).get<double>());
        r.poses[image] = pose;
      }
  } catch (const json::exception& error) {
    throw InputError(InputMessage(name, field, std::string("missing or of the wrong type (") + error.what() + ")"));
  }
  return r;
}

}  // namespace

std::string CalibrationJsonText(const CalibrationRecord& record) { return ToJson(record).dump(2) + "\n"; }

void WriteCalibrationJson(const CalibrationRecord& record, const std::string& path) {
  const std::string text = CalibrationJsonText(record);
  WriteFileAtomically(path, [&](std::ostream& out) { out << text; });
}

CalibrationRecord ParseCalibrationJson(const std::string& text, const std::string& name) {
  json j;
  try {
    j = json::parse(text);
  } catch (const json::exception&) {
    throw InputError(InputMessage(name, "", "is not valid JSON"));
  }
  return FromJson(j, name);
}

CalibrationRecord ReadCalibrationJson(const std::string& path) { return FromJson(ReadJsonFile(path), path); }

void WriteProjectionDiffJson(const ProjectionDiff& diff, const std::map<std::string, std::string>& labels,
                             const std::string& path) {
  json j = DiffSummary(diff);
  for (const auto& [key, value] : labels) j[key] = value;
  j["definition"] =
      "the points distance_mm along each field pixel's ray through a (from its reflection point), moved by the rigid "
      "motion that best aligns them (fitted at aligned_at_mm: distance_mm unless --align-at-mm was given), "
      "projected through b; differences are b's pixel minus the field pixel; moved_off_mirror: field pixels whose "
      "point that motion, fitted at another distance, moved off b's mirror (not compared)";
  for (size_t k = 0; k < diff.pixels.size(); ++k)
    j["pixels"].push_back({{"pixel", {diff.pixels[k].x(), diff.pixels[k].y()}},
                           {"difference_px", {NumberOrNull(diff.difference_px[k].x()), NumberOrNull(diff.difference_px[k].y())}}});
  const std::string text = j.dump(1) + "\n";
  WriteFileAtomically(path, [&](std::ostream& out) { out << text; });
}

}  // namespace omnical

#include "calib/calibrate.h"

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <utility>

#include "calib/board_size_screen.h"
#include "calib/checkerboard_completion.h"
#include "calib/cross_validation.h"
#include "calib/fit_covariance.h"
#include "calib/fold_scores.h"
#include "calib/image_file.h"
#include "calib/lens_choice.h"
#include "calib/rim_circle.h"
#include "model/input_error.h"
#include "model/model_registry.h"
#include "model/object_distance.h"

namespace omnical {
namespace {

// Targets whose distances from the lens span less than this ratio count as "one
// distance" (the warning above the fit's results).
constexpr double kOneDistanceRatio = 1.5;

// Where the two halves are compared when the user names no distance: a room's far wall.
constexpr double kDefaultCrossValidationDistanceMm = 2000.0;

// The detections without corners the target does not have and without corners marked
// unrefined (the detector's own position, ~5x worse than refined ones: unweighted among
// them they biased the mirror's size on renders); *unrefined counts the latter. Throws if
// no corner id matches.
DetectionSet FittableCorners(const CalibrationInput& input, DetectionSet detections, int* unrefined) {
  std::set<int> ids;
  for (const TargetCorner& c : input.target.corners()) ids.insert(c.id);
  int matched = 0;
  *unrefined = 0;
  for (ImageDetections& image : detections.images) {
    image.corners.erase(std::remove_if(image.corners.begin(), image.corners.end(),
                                       [&](const CornerObservation& c) {
                                         if (!ids.count(c.id)) return true;
                                         ++matched;
                                         *unrefined += c.unrefined;
                                         return c.unrefined;
                                       }),
                        image.corners.end());
  }
  if (matched == 0)
    throw InputError(InputMessage(input.target_name, "", "the target spec matches no corner id in " + input.source));
  return detections;
}

// Without the images in `names` (views refused by the board-size screen).
DetectionSet WithoutImages(DetectionSet detections, const std::set<std::string>& names) {
  auto& images = detections.images;
  images.erase(std::remove_if(images.begin(), images.end(), [&](const ImageDetections& i) { return names.count(i.image) > 0; }),
               images.end());
  return detections;
}

struct UsableViews {
  DetectionSet detections;  // the views with a starting pose
  std::vector<TargetPose> poses;
  int observations = 0;  // corners
};

// Views with at least 4 corners and a pose through `start`; throws when they cannot
// determine the sensor.
UsableViews ViewsForFit(const Sensor& start, const CalibrationInput& input, const DetectionSet& detections,
                        std::vector<CalibrationWarning>* warnings) {
  UsableViews views;
  views.detections = detections;
  views.detections.images.clear();
  for (const ImageDetections& image : detections.images) {
    TargetPose pose;
    if (image.corners.size() < 4 || !InitialTargetPose(start, input.target, image, &pose)) {
      const std::string count = std::to_string(image.corners.size());
      const std::string why =
          !image.corners.empty() ? (image.corners.size() < 4 ? "only " + count + " usable corners"
                                                             : "no starting pose from its " + count + " usable corners")
          : input.target.type() == CalibrationTarget::Type::kCheckerboard
              ? "no complete checkerboard of " + std::to_string(input.target.cols()) + " x " +
                    std::to_string(input.target.rows()) + " inner corners found"
              : "no tag of the target found";
      warnings->push_back({WarningCode::kViewSkipped, image.image, image.image + ": " + why + ", view skipped", why});
      continue;
    }
    views.detections.images.push_back(image);
    views.poses.push_back(pose);
  }
  // Enough data for what is asked: 2 residuals per corner against 6 per view plus the
  // sensor's free parameters, and views that differ (one pose says nothing about the
  // mirror).
  for (const ImageDetections& image : views.detections.images) views.observations += static_cast<int>(image.corners.size());
  const int sensor_parameters = static_cast<int>(SensorParameters(start).size());
  const int view_count = static_cast<int>(views.detections.images.size());
  if (view_count < 3 || 2 * views.observations < 2 * (6 * view_count + sensor_parameters))
    throw InputError(InputMessage(input.source, "images",
                                  std::to_string(view_count) + " usable views with " + std::to_string(views.observations) +
                                      " corners are too few for the " + std::to_string(sensor_parameters) +
                                      " sensor parameters (need >= 3 views)"));
  double spread_deg = 0.0, spread_mm = 0.0;
  for (const TargetPose& pose : views.poses) {
    spread_deg = std::max(spread_deg, pose.camera_from_target_rotation.angularDistance(views.poses[0].camera_from_target_rotation) * 180.0 / M_PI);
    spread_mm = std::max(spread_mm, (pose.camera_from_target_translation_mm - views.poses[0].camera_from_target_translation_mm).norm());
  }
  if (spread_deg < 1.0 && spread_mm < 5.0)
    throw InputError(InputMessage(input.source, "images", "all views show the target at one pose: move it between images"));
  return views;
}

// Moves the views named in `names` out of `views` (the held-out views).
UsableViews SplitOff(UsableViews* views, const std::set<std::string>& names) {
  UsableViews held;
  held.detections = views->detections;
  held.detections.images.clear();
  UsableViews kept = held;
  for (size_t v = 0; v < views->detections.images.size(); ++v) {
    UsableViews& to = names.count(views->detections.images[v].image) ? held : kept;
    to.detections.images.push_back(views->detections.images[v]);
    to.poses.push_back(views->poses[v]);
    to.observations += static_cast<int>(views->detections.images[v].corners.size());
  }
  *views = std::move(kept);
  return held;
}

// Held-out views fitting over 25 % worse than the training views: more than the few-percent
// spread of per-view RMS a well-posed fit shows between views of one set (the BabelCalib
// protocol's usual reading). `which` names the held-out views and leads the text.
void WarnIfHeldOutWorse(const std::string& which, double held_rms_px, double training_rms_px,
                        std::vector<CalibrationWarning>* warnings) {
  if (!(held_rms_px > 1.25 * training_rms_px)) return;
  char text[300];
  std::snprintf(text, sizeof text,
                " %.3f px RMS against %.3f px for the training views: the model does not predict new views as well "
                "as it fits its own (too flexible, or too few views)",
                held_rms_px, training_rms_px);
  warnings->push_back({WarningCode::kHeldOutWorse, "", which + text});
}

// The views to keep out: those named, or `holdout` spread evenly over the usable views;
// leaving >= 3.
// Named views need only be images of the set here: a view can become usable in a later
// detection pass (a checkerboard found through the first fit; --holdout-folds names the
// views of the last), so whether each is usable is checked after it (CheckHeldOutNamesUsable).
std::set<std::string> HoldoutNames(const CalibrationInput& input, const DetectionSet& all, const UsableViews& views,
                                   int holdout, const std::set<std::string>& named) {
  std::set<std::string> names;
  const size_t total = views.detections.images.size();
  const size_t asked = named.empty() ? static_cast<size_t>(std::max(holdout, 0)) : named.size();
  if (asked > 0 && total < asked + 3)
    throw InputError(InputMessage(input.source, "holdout",
                                  std::to_string(asked) + " views held out of " + std::to_string(total) +
                                      " usable leave fewer than 3 for the fit"));
  if (!named.empty()) {
    for (const std::string& name : named) {
      const bool found = std::any_of(all.images.begin(), all.images.end(),
                                     [&](const ImageDetections& image) { return image.image == name; });
      if (!found) throw InputError(InputMessage(input.source, "holdout", name + ": not a usable view"));
    }
    names = named;
  } else if (holdout > 0) {
    for (size_t v : EvenlySpreadIndices(total, static_cast<size_t>(holdout))) names.insert(views.detections.images[v].image);
  }
  return names;
}

// After the last detection pass: every named held-out view was usable (split off) in some
// pass. One usable in the first pass and not in a later one is not refused: a fold of
// --holdout-folds refines its corners through its own fit, and one view lost there should
// not end the whole evaluation.
void CheckHeldOutNamesUsable(const CalibrationInput& input, const std::set<std::string>& named,
                             const std::set<std::string>& ever_held) {
  for (const std::string& name : named)
    if (!ever_held.count(name)) throw InputError(InputMessage(input.source, "holdout", name + ": not a usable view"));
}

// Adds the names of `held`'s views to *names.
void AddViewNames(const UsableViews& held, std::set<std::string>* names) {
  for (const ImageDetections& image : held.detections.images) names->insert(image.image);
}

// The rim circle of the images a detections file names (the median over those that read).
std::optional<RimCircle> RimOfImages(const DetectionSet& detections) {
  std::vector<RimCircle> circles;
  for (const ImageDetections& image : detections.images) {
    const cv::Mat grey = ReadImageFile(image.image, cv::IMREAD_GRAYSCALE);
    if (grey.empty()) continue;
    if (auto circle = DetectRimCircle(grey)) circles.push_back(*circle);
  }
  return MedianRimCircle(circles);
}

// The corners, detected here (with the images' rim circles if asked) or given.
DetectedImages FindCorners(const CalibrationInput& input, const CalibrationOptions& options,
                           const std::optional<Sensor>& through, bool rim_circles, bool omni_search = true,
                           bool refine = true, bool fit_whole_tags = true, const BoardWarp& warp = BoardWarp()) {
  DetectionOptions detection;
  detection.guess = through;
  detection.refine = refine;
  detection.fit_whole_tags = fit_whole_tags;
  detection.board_warp = warp;
  detection.rim_circles = rim_circles;
  detection.threads = options.threads;
  detection.progress = options.progress;
  detection.omni_search = omni_search;
  DetectedImages found = input.image_paths.empty() ? DetectImages(input.target, input.images, detection)
                                                   : DetectImageFiles(input.target, input.image_paths, input.source, detection);
  found.detections.target_spec = input.target_name;
  return found;
}

// Checkerboards the first search missed (an image without one: a board curved near the
// rim or the inner radius), searched for through virtual views of a fitted sensor only;
// true when one was found (it replaces the empty entry).
bool FindMissedCheckerboards(const CalibrationInput& input, const CalibrationOptions& options, const Sensor& through,
                             DetectionSet* detections) {
  std::set<std::string> missed;
  for (const ImageDetections& image : detections->images)
    if (image.corners.empty()) missed.insert(image.image);
  if (missed.empty()) return false;
  CalibrationInput again = input;
  again.image_paths.clear();
  again.images.clear();
  for (const std::string& path : input.image_paths)
    if (missed.count(path)) again.image_paths.push_back(path);
  for (const NamedImage& image : input.images)
    if (missed.count(image.name)) again.images.push_back(image);
  const DetectionSet found =
      FindCorners(again, options, through, false, /*omni_search=*/false, /*refine=*/false).detections;
  bool any = false;
  for (const ImageDetections& image : found.images) {
    if (image.corners.empty()) continue;
    for (ImageDetections& entry : detections->images)
      if (entry.image == image.image) entry = image;
    any = true;
  }
  return any;
}

// Checkerboard corners found without refinement, refined through a fitted sensor
// (calib/image_detection.h, RefineFoundCorners).
DetectionSet CornersRefinedThrough(const CalibrationInput& input, const CalibrationOptions& options,
                                         const Sensor& through, const BoardWarp& warp, const DetectionSet& found) {
  DetectionOptions detection;
  detection.guess = through;
  detection.board_warp = warp;
  detection.checkerboard_edges = options.checkerboard_edges.value_or(true) &&
                                 input.target.type() == CalibrationTarget::Type::kCheckerboard;
  detection.threads = options.threads;
  detection.progress = options.progress;
  std::map<std::string, const cv::Mat*> in_memory;
  for (const NamedImage& image : input.images) in_memory[image.name] = &image.grey;
  return RefineFoundCorners(
      input.target, found,
      [&](const std::string& name) {
        if (!input.image_paths.empty()) return ReadImageFile(name, cv::IMREAD_GRAYSCALE);
        const auto it = in_memory.find(name);
        return it == in_memory.end() ? cv::Mat() : *it->second;
      },
      detection);
}

// The fit's tolerances: the guess's (those that apply to the fitted family), then the
// options' (which win), centred on the start's values.
FitOptions FitOptionsFor(const CalibrationInput& input, const CalibrationOptions& options, const Sensor& start,
                         std::vector<CalibrationWarning>* warnings) {
  FitOptions fit = FitOptions::DefaultsFor(start);
  // A pinhole in front of a free-form mirror the rim circle started: the gauges of an
  // unknown shape, with no design to hold them at (CalibrationOptions::lens). Free, m and
  // decenter slid along their valleys (std 5.5 % of m on
  // rendered/ohte-sph-misaligned-near) and a decenter started a wrong tilt basin. A
  // sphere's or a paraboloid's are observable, as with a guess.
  const bool free_form = std::visit([](const auto& model) { return HasFreeFormTerms(model.mirror); }, start.model());
  if (!input.guess && std::string(start.lens_name()) == "pinhole" && free_form) fit.refine.m = fit.refine.decenter = false;
  if (options.tangential == kTangentialOn) fit.refine.tangential = true;
  if (const std::string why = fit.refine.Hold(options.fixed); !why.empty()) throw InputError(why);
  fit.robust_loss_px = options.loss_px;
  fit.fit_board_warp = options.board_warp;
  fit.fit_board_relief = options.board_warp && options.board_relief == kReliefOn;
  fit.view_noise_weights = options.view_weights;
  fit.solver.max_num_iterations = options.max_iterations;
  fit.threads = options.threads;
  if (const std::string why = fit.Check(); !why.empty()) throw InputError(why);
  fit.tolerances = ExpandTolerances(input.guess_tolerances);
  for (auto it = fit.tolerances.begin(); it != fit.tolerances.end();) {
    FitOptions one;
    one.tolerances = {*it};
    if (one.CheckFor(start).empty()) {
      ++it;
      continue;
    }
    // Converted to another family: the old family's shape tolerances do not apply.
    warnings->push_back({WarningCode::kToleranceNotApplicable, it->first,
                         input.guess_name + ": the tolerance on " + it->first + " does not apply to a " +
                             start.profile_name() + " mirror and is not used"});
    it = fit.tolerances.erase(it);
  }
  for (const auto& [name, value] : ExpandTolerances(options.tolerances)) fit.tolerances[name] = value;
  if (const std::string why = fit.CheckFor(start); !why.empty()) throw InputError("tolerances: " + why);
  for (const ParameterEstimate& p : SensorParameters(start)) fit.design[p.name] = p.value;
  fit.progress = options.progress;
  return fit;
}

// Stability: the fit repeated without each view in turn; the spread of each parameter.
std::map<std::string, CalibrationRecord::Spread> LeaveOneOut(const Sensor& start, const CalibrationInput& input,
                                                              const UsableViews& views, FitOptions quick,
                                                              const ProgressCallback& callback) {
  std::map<std::string, std::vector<double>> folds;
  quick.compute_covariance = false;
  quick.progress = nullptr;  // the folds report as one stage, checked between fits
  ProgressReporter progress(callback, "leave-one-out", static_cast<long>(views.detections.images.size()));
  for (size_t left_out = 0; left_out < views.detections.images.size(); ++left_out) {
    DetectionSet subset = views.detections;
    std::vector<TargetPose> subset_poses = views.poses;
    subset.images.erase(subset.images.begin() + left_out);
    subset_poses.erase(subset_poses.begin() + left_out);
    const FitResult fold = FitSensor(start, input.target, subset, subset_poses, quick);
    for (const ParameterEstimate& p : fold.parameters) folds[p.name].push_back(p.value);
    progress.Step();
  }
  std::map<std::string, CalibrationRecord::Spread> spread;
  for (const auto& [name, values] : folds) {
    const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
    double mean = 0.0, square = 0.0;
    for (double v : values) mean += v;
    mean /= values.size();
    for (double v : values) square += (v - mean) * (v - mean);
    spread[name] = {*lo, *hi, std::sqrt(square / values.size())};
  }
  return spread;
}

bool HoldsTangential(const std::set<std::string>& fixed) {
  RefineOptions held;
  held.Hold(fixed);  // an unknown name is the fit's error to report
  return !held.tangential;
}

}  // namespace

std::string CalibrationOptions::Check() const {
  const std::vector<std::string> profiles = CalibrationProfileNames();
  if (!profile.empty() && std::find(profiles.begin(), profiles.end(), profile) == profiles.end())
    return "profile: unknown mirror family '" + profile + "' (" + JoinChoices(profiles) + ")";
  if (!(rim_field_deg >= 10.0 && rim_field_deg <= 170.0)) return "rim_field_deg: must lie in 10-170 deg";
  if (!lens.empty() && lens != "orthographic" && lens != "pinhole" && lens != kChooseLens)
    return "lens: the rim circle starts an orthographic or a pinhole lens, or 'auto' (got '" + lens + "')";
  if (!tangential.empty() && tangential != kTangentialOff && tangential != kTangentialOn && tangential != kChooseTangential)
    return "tangential: off, on or auto (got '" + tangential + "')";
  if ((tangential == kTangentialOn || tangential == kChooseTangential) && HoldsTangential(fixed))
    return "tangential/fixed: tangential " + tangential + " fits p1, p2, which fixed holds";
  if (!board_relief.empty() && board_relief != kReliefOff && board_relief != kReliefOn && board_relief != kChooseRelief)
    return "board_relief: off, on or auto (got '" + board_relief + "')";
  if ((board_relief == kReliefOn || board_relief == kChooseRelief) && !board_warp)
    return "board_relief: " + board_relief +
           " fits the relief on top of the board's warp, which board_warp off holds flat";
  if (!(loss_px >= 0.0 && std::isfinite(loss_px))) return "loss_px: must be >= 0 and finite";
  if (max_iterations < 1) return "max_iterations: must be >= 1";
  // Pass 2 re-detects through the first fit; an aprilgrid's later passes through the last.
  if (detection_passes < 1 || detection_passes > 5) return "detection_passes: must be 1..5";
  if (threads < 1) return "threads: must be >= 1";
  for (double d : distances_mm)
    if (const std::string why = ObjectDistanceProblem(d); !why.empty()) return "distances_mm: " + why;
  for (double n : distances_n)
    if (!(n > 0.0 && std::isfinite(n))) return "distances_n: must be > 0 and finite";
  if (!(max_predicted_error_px >= 0.0 && std::isfinite(max_predicted_error_px))) return "max_predicted_error_px: must be >= 0";
  if (!(predicted_error_step_px > 0.0 && std::isfinite(predicted_error_step_px))) return "predicted_error_step_px: must be > 0";
  if (holdout_views < 0) return "holdout_views: must be >= 0";
  if (holdout_folds < 0) return "holdout_folds: must be >= 0";
  if (holdout_folds > 0 && (holdout_views > 0 || !holdout_images.empty()))
    return "holdout_folds/holdout_views: each fold keeps its own views out: give one of them";
  if (holdout_views > 0 && !holdout_images.empty())
    return "holdout_views/holdout_images: give the count or the names, not both";
  if (knots != 0 && knots != kChooseKnots && (knots < SplineProfile<double>::kMinKnots || knots > SplineProfile<double>::kMaxKnots))
    return "knots: must be 4..16 (or auto)";
  if (cross_validation_distance_mm != 0.0)
    if (const std::string why = ObjectDistanceProblem(cross_validation_distance_mm); !why.empty())
      return "cross_validation_distance_mm: " + why + " (0: the default)";
  return "";
}

namespace {

// One calibration (no folds). From images, the first detection pass is `reused` when given,
// else run and, when `kept` is given, copied there. That pass depends on the images, the
// target, the guess and the detection options, none of which a held-out fold changes (its
// views are detected with the rest and split off after), so the folds reuse the full set's:
// on the real dev set it was ~70 % of each calibration's time. `folds_knots`: a held-out
// fold of a calibration whose default knot choice chose a count (or none: 0), fitted as it
// was, through the family until the passes end, then as a spline of that count.
CalibrationResult CalibrateOnce(const CalibrationInput& input, const CalibrationOptions& options,
                                const DetectedImages* reused, DetectedImages* kept,
                                std::optional<int> folds_knots = std::nullopt);

// CalibrationOptions::holdout_folds: the full set's calibration, then one per fold with
// that fold's views kept out (fitted without them, and refined in the later detection
// passes through fits without them, as `holdout_views`).
CalibrationResult CalibrateWithHeldOutFolds(const CalibrationInput& input, const CalibrationOptions& options) {
  CalibrationOptions full_options = options;
  full_options.holdout_folds = 0;
  DetectedImages first_pass;
  CalibrationResult result = CalibrateOnce(input, full_options, nullptr, &first_pass);
  std::vector<std::string> usable;  // the fitted views, in the input's order
  for (size_t v = 0; v < result.views.images.size(); ++v)
    if (v >= result.fit.view_left_out.size() || result.fit.view_left_out[v].empty())
      usable.push_back(result.views.images[v].image);
  const size_t per_fold = static_cast<size_t>(options.holdout_folds);
  if (usable.size() < per_fold + 3)
    throw InputError(InputMessage(input.source, "holdout_folds",
                                  std::to_string(per_fold) + " views held out of " + std::to_string(usable.size()) +
                                      " usable leave fewer than 3 for the fit"));
  const size_t fold_count = (usable.size() + per_fold - 1) / per_fold;
  CalibrationOptions fold_options = full_options;
  fold_options.cross_validate = false;  // each fold answers one question: how well it predicts its views
  fold_options.leave_one_out = false;
  // The lens the full set used, chosen or not (choosing again would be 10 fits more per
  // fold, and a fold could judge another lens than the calibration written).
  if (!input.guess) fold_options.lens = result.sensor.lens_name();
  if (result.record.profile_choice) fold_options.profile = result.sensor.profile_name();  // the same for the mirror
  // ... and its knot count, or none: `--knots auto`'s as asked for, the default's through
  // the family, as the full set (CalibrateOnce's folds_knots).
  std::optional<int> folds_knots;
  if (const auto& knots = result.record.knot_choice) {
    if (options.knots == kChooseKnots) {
      fold_options.profile = result.sensor.profile_name();
      fold_options.knots = knots->chosen;
    } else {
      fold_options.profile = knots->base_profile;
      folds_knots = knots->chosen;
    }
  }
  if (const auto& tangential = result.record.tangential_choice)  // the same for the tangential terms
    fold_options.tangential = tangential->chosen == kTangentialCandidates[1] ? kTangentialOn : kTangentialOff;
  else if (fold_options.tangential.empty())
    fold_options.tangential = kTangentialOff;  // held: no choice was made
  if (fold_options.lens == "orthographic") fold_options.tangential = kTangentialOff;  // which it has none of
  // And the board's relief.
  if (const auto& relief = result.record.relief_choice)
    fold_options.board_relief = relief->chosen == kReliefCandidates[1] ? kReliefOn : kReliefOff;
  else if (fold_options.board_relief.empty())
    fold_options.board_relief = kReliefOff;
  std::vector<CalibrationWarning> warnings;  // the folds' own, added to the full set's below
  HeldOutFolds folds;
  folds.views_per_fold = options.holdout_folds;
  double held_square_px2 = 0.0, training_square_px2 = 0.0;
  ProgressReporter progress(options.progress, "holdout folds", static_cast<long>(fold_count));
  for (size_t f = 0; f < fold_count; ++f) {
    fold_options.holdout_images.clear();
    for (size_t v = f; v < usable.size(); v += fold_count) fold_options.holdout_images.insert(usable[v]);
    const CalibrationRecord record = CalibrateOnce(input, fold_options, &first_pass, nullptr, folds_knots).record;
    const HeldOutViews& held = *record.holdout;
    HeldOutFolds::Fold fold;
    fold.images = held.images;
    fold.rms_px = held.rms_px;
    fold.corners = held.corners;
    fold.training_rms_px = record.rms_all_px;
    fold.training_corners = record.observations;
    folds.folds.push_back(fold);
    for (const auto& [image, rms] : held.per_view_rms_px) folds.per_view_rms_px[image] = rms;
    for (const auto& [image, why] : held.not_evaluated)
      warnings.push_back({WarningCode::kViewLeftOut, image, image + ": held-out view not evaluated: " + why});
    if (std::isfinite(fold.rms_px) && fold.corners > 0) {
      held_square_px2 += fold.corners * fold.rms_px * fold.rms_px;
      folds.corners += fold.corners;
    }
    if (std::isfinite(fold.training_rms_px) && fold.training_corners > 0) {
      training_square_px2 += fold.training_corners * fold.training_rms_px * fold.training_rms_px;
      folds.training_corners += fold.training_corners;
    }
    progress.Step();
  }
  if (folds.corners > 0) folds.rms_px = std::sqrt(held_square_px2 / folds.corners);
  if (folds.training_corners > 0) folds.training_rms_px = std::sqrt(training_square_px2 / folds.training_corners);
  WarnIfHeldOutWorse("every view held out once (" + std::to_string(folds.folds.size()) + " folds):", folds.rms_px,
                     folds.training_rms_px, &warnings);
  for (CalibrationWarning& warning : warnings) {
    result.record.warnings.push_back(warning.text);
    result.warnings.push_back(std::move(warning));
  }
  result.record.holdout_folds = folds;
  return result;
}

CalibrationResult CalibrateOnce(const CalibrationInput& input, const CalibrationOptions& options,
                                const DetectedImages* reused, DetectedImages* kept, std::optional<int> folds_knots) {
  const int sources = !input.image_paths.empty() + !input.images.empty() + input.detections.has_value();
  if (sources != 1) throw InputError("images: give either images (detected here) or detections");
  const bool from_images = !input.detections;
  if (input.guess && !options.lens.empty())
    throw InputError(InputMessage(input.guess_name, "lens", "the guess has its lens (" + std::string(input.guess->lens_name()) +
                                                                "): lens chooses the rim circle's start, without a guess"));
  if (input.guess && options.profile == kChooseProfile)
    throw InputError(InputMessage(input.guess_name, "profile",
                                  "auto chooses an unknown mirror's family, without a guess (the guess's is " +
                                      std::string(input.guess->profile_name()) + "; give a family to convert it to)"));
  // Without a guess the lens, and a pinhole's p1, p2, are chosen by held-out folds unless
  // asked for: the rim circle cannot tell a telecentric lens from a perspective camera, and
  // through the wrong one a set's own corners still fit while new views do not (the
  // bundled mixed renders: held out 2.61 px through the orthographic, 0.30 through the
  // pinhole; docs/calibrate.md). A set too small for folds keeps the orthographic lens,
  // p1, p2 held.
  const bool lens_by_default = !input.guess && options.lens.empty();
  const bool tangential_by_default = !input.guess && options.tangential.empty();
  // p1, p2 are a pinhole's: refused where the lens is known to be orthographic (where the
  // lens is chosen, an orthographic choice leaves them out).
  const std::string known_lens = input.guess ? input.guess->lens_name()
                                 : options.lens.empty() || options.lens == kChooseLens ? ""
                                                                                       : options.lens;
  if (!options.tangential.empty() && options.tangential != kTangentialOff && known_lens == "orthographic") {
    const std::string why = "the orthographic lens has no tangential distortion (p1, p2 are a pinhole's)";
    throw InputError(input.guess ? InputMessage(input.guess_name, "tangential", why)
                                 : "tangential: " + why + "; give lens pinhole or auto");
  }
  // Said, not ignored: how a checkerboard's corners are refined is a step of the second
  // detection pass over its images (unset: edges wherever that applies).
  const bool refinement_asked = options.checkerboard_edges.has_value();
  if (refinement_asked && !from_images)
    throw InputError("checkerboard_edges: chooses how the corners found in images are refined, not corners given as "
                     "detections (detect --sensor ... --checkerboard-edges refines them there)");
  if (refinement_asked && input.target.type() != CalibrationTarget::Type::kCheckerboard)
    throw InputError("checkerboard_edges: the target is not a checkerboard");
  if (refinement_asked && options.detection_passes < 2)
    throw InputError("checkerboard_edges/detection_passes: the corners are refined in the second detection pass: "
                     "give 2 or more");
  std::vector<CalibrationWarning> warnings;
  CalibrationRecord record;
  std::vector<PredictedError> predicted;
  std::vector<std::string> distance_labels;
  DetectionSet detections;
  std::optional<RimCircle> rim;
  if (from_images) {
    // Checkerboard corners are refined in the second pass, through the first fit; aprilgrid
    // tags are fitted whole (calib/tag_template_fit.h) in every pass after the first: this
    // one's corners only start the first fit when a second pass follows (the whole-tag fits
    // are three quarters of a detection's time).
    // The rim circles start the fit without a guess, and place the rim for later passes.
    DetectedImages found;
    if (reused) {
      found = *reused;
    } else {
      found = FindCorners(input, options, input.guess, !input.guess || options.detection_passes > 1, true,
                          input.target.type() != CalibrationTarget::Type::kCheckerboard, options.detection_passes < 2);
      if (kept) *kept = found;
    }
    detections = std::move(found.detections);
    warnings = std::move(found.warnings);
    rim = MedianRimCircle(found.rim_circles);
  } else {
    detections = *input.detections;
    // Corners fitted to another board than the one they were found on calibrate without
    // complaint (a 50 mm aprilgrid for 30 mm detections: 0.11 px RMS, a mirror 13 % too big).
    if (const std::string found_on = detections.target_description;
        !found_on.empty() && found_on != input.target.Describe())
      throw InputError(InputMessage(input.source, "target_description",
                                    "the corners were found on another board (" + found_on + ") than the target given (" +
                                        input.target.Describe() +
                                        "): detect again with it (or, if only the print's measured size changed and no "
                                        "sensor guess was used to detect, delete target_description from the file)"));
    if (!input.guess) rim = RimOfImages(detections);
  }
  // The starting sensor: the guess (in another profile family if asked), or, with no
  // guess, the rim circle of the images through a lens and a mirror family (each's, to
  // choose one; the lens is chosen through the first family).
  const bool profile_unset_or_auto = !input.guess && (options.profile.empty() || options.profile == kChooseProfile);
  const std::string rim_profile = profile_unset_or_auto ? kProfileCandidates[0] : options.profile;
  const auto rim_start = [&](const std::string& lens, const std::string& profile) {
    const Sensor start = SensorFromRimCircle(*rim, detections.image_width_px, detections.image_height_px, profile,
                                             options.rim_field_deg, lens);
    return options.knots > 0 && profile == "spline" ? ConvertProfile(start, "spline", options.knots) : start;
  };
  // The rim circle's start through `lens` and `profile` as a candidate for held-out folds;
  // none (scored NaN) where it cannot start (a rim ray it cannot reach, a tolerance on a
  // parameter it lacks) or pose every view.
  const auto rim_candidate = [&](const std::string& lens, const std::string& profile, const DetectionSet& views,
                                 std::vector<CalibrationWarning>* warnings_out) -> std::optional<FoldCandidate> {
    try {
      Sensor start = rim_start(lens, profile);
      std::vector<TargetPose> poses(views.images.size());
      for (size_t v = 0; v < poses.size(); ++v)
        if (!InitialTargetPose(start, input.target, views.images[v], &poses[v])) return std::nullopt;
      FitOptions start_options = FitOptionsFor(input, options, start, warnings_out);
      return FoldCandidate{std::move(start), std::move(start_options), std::move(poses)};
    } catch (const InputError&) {
      return std::nullopt;
    }
  };
  std::string profile_said = rim_profile + " mirror", lens_said;  // the rim circle's start, as record.start says it
  std::optional<Sensor> start_sensor;
  if (input.guess) {
    start_sensor = options.profile.empty() ? *input.guess : ConvertProfile(*input.guess, options.profile);
    const bool vowel = !options.profile.empty() && std::string("aeiou").find(options.profile[0]) != std::string::npos;
    record.start = input.guess_name + (options.profile.empty() ? "" : (vowel ? " as an " : " as a ") + options.profile + " mirror");
  } else {
    if (!rim)
      throw InputError(InputMessage(input.source, "images", "no mirror rim circle found to start from; give a sensor guess"));
    const std::string lens = options.lens.empty() || options.lens == kChooseLens ? "orthographic" : options.lens;
    start_sensor = rim_start(lens, rim_profile);
    lens_said = lens + " lens";
    record.start = "rim circle, " + profile_said + ", " + lens_said;
    record.rim_circle = CalibrationRecord::RimCircleRecord{rim->centre_px, rim->radius_px, rim->inlier_fraction, rim->rms_px};
  }
  if (options.knots != 0) {
    const std::string profile = start_sensor->profile_name();
    if (profile != "spline")
      throw InputError(
          InputMessage("knots", "", "only the spline profile has knots (profile: " + profile + "; ask for --profile spline)"));
    if (options.knots > 0) start_sensor = ConvertProfile(*start_sensor, "spline", options.knots);
  }
  const Sensor& guess = *start_sensor;
  // n counts the design's rim radii; from the rim circle the nominal one's (a pinhole's
  // start reaches past it, calib/initial_sensor.h).
  const double design_rim_mm = input.guess ? guess.rim_radius_mm() : kNominalRimRadiusMm;
  for (double n : options.distances_n)  // known only now, and before any fit
    if (const std::string why = ObjectDistanceProblem(n * design_rim_mm); !why.empty())
      throw InputError("distances_n: " + why);
  if (detections.image_width_px != guess.image_width_px() || detections.image_height_px != guess.image_height_px())
    throw InputError(InputMessage(input.source, "image_size",
                                  std::to_string(detections.image_width_px) + " x " + std::to_string(detections.image_height_px) +
                                      " differs from the sensor's " + std::to_string(guess.image_width_px()) + " x " +
                                      std::to_string(guess.image_height_px())));
  FitOptions fit_options = FitOptionsFor(input, options, guess, &warnings);

  int unrefined = 0;
  UsableViews views = ViewsForFit(guess, input, FittableCorners(input, detections, &unrefined), &warnings);
  const std::set<std::string> holdout_names =
      HoldoutNames(input, detections, views, options.holdout_views, options.holdout_images);
  UsableViews held = SplitOff(&views, holdout_names);
  std::set<std::string> ever_held;  // the named views usable in some pass
  AddViewNames(held, &ever_held);
  // Too few views to halve: said before the fit, not after it (the halves are of the views
  // the fit keeps, so this is necessary, and CrossValidateHalves checks again).
  if (const size_t half = views.detections.images.size() / 2; options.cross_validate && half < 3)
    throw InputError("cross_validate: half 2 has " + std::to_string(half) +
                     " views (need >= 3 per half, >= 6 usable views in all)");
  // Without a guess, the lens by held-out folds on the first pass's corners, before the
  // corners are refined through a fit with it (calib/lens_choice.h).
  const bool foldable = static_cast<int>(views.detections.images.size()) >= kMinViewsForFolds;
  // p1, p2 asked for where the default cannot choose the lens: the orthographic it keeps has none.
  if (lens_by_default && !foldable && !tangential_by_default && options.tangential != kTangentialOff)
    throw InputError("tangential: the lens is chosen by held-out folds, which need >= " +
                     std::to_string(kMinViewsForFolds) + " usable views (" +
                     std::to_string(views.detections.images.size()) +
                     " given), and the orthographic lens kept instead has no tangential distortion; give lens pinhole");
  if (options.board_relief == kChooseRelief && !foldable)
    throw InputError(
        "board_relief: auto chooses by held-out folds, which need >= " + std::to_string(kMinViewsForFolds) +
        " usable views (" + std::to_string(views.detections.images.size()) + " given); give on or off");
  // A choice by held-out folds starts the fit from the candidate it chose: the start sensor
  // (`guess` refers to it), its fit options and initial poses. The current start is always
  // a choice's candidate, so an unchanged choice copies what is already there (and one no
  // candidate could start is never chosen: unscored, the first, the current start, is kept).
  const auto start_from_chosen = [&](const NamedChoice& choice,
                                     const std::vector<std::optional<FoldCandidate>>& candidates) {
    const size_t chosen =
        std::find(choice.candidates.begin(), choice.candidates.end(), choice.chosen) - choice.candidates.begin();
    if (chosen >= candidates.size() || !candidates[chosen]) return;
    const FoldCandidate& start = *candidates[chosen];
    start_sensor = start.start;
    fit_options = start.options;
    views.poses = start.initial_poses;
  };
  if (options.lens == kChooseLens || (lens_by_default && foldable)) {
    std::vector<std::optional<FoldCandidate>> candidates;
    for (const std::string& lens : kLensCandidates)
      candidates.push_back(lens == guess.lens_name()
                               ? std::optional<FoldCandidate>(FoldCandidate{guess, fit_options, views.poses})
                               : rim_candidate(lens, rim_profile, views.detections, &warnings));
    const NamedChoice& choice =
        *(record.lens_choice = ChooseByHeldOutFolds(kLensCandidates, candidates, kLensScoreTolerance, input.target,
                                                    views.detections, options.threads, "lens", options.progress));
    start_from_chosen(choice, candidates);
    const bool scored = choice.AnyScored();
    lens_said = choice.chosen + " lens" + (scored ? " (chosen by held-out folds)" : "");
    record.start = "rim circle, " + profile_said + ", " + lens_said;
    if (!scored)
      warnings.push_back({WarningCode::kLensNotChosen, "lens",
                          "neither lens could be fitted to every held-out fold of the views (a view where no other "
                          "reaches, or no valid sensor?); the " + choice.chosen + " lens is kept"});
    if (!tangential_by_default && options.tangential != kTangentialOff && choice.chosen == "orthographic")
      warnings.push_back({WarningCode::kTangentialNotFitted, "tangential",
                          "tangential " + options.tangential + ": the orthographic lens was chosen, which has no "
                          "tangential distortion; p1, p2 are not fitted"});
  }
  // Without a guess, the mirror family by held-out folds through the lens chosen, on the same
  // corners (calib/profile_choice.h). The first family's candidate is the lens choice's
  // chosen one: its score is reused (5 fits fewer).
  if (options.profile == kChooseProfile || (!input.guess && options.profile.empty() && foldable)) {
    const std::string lens = guess.lens_name();
    std::optional<KnownScore> first_score;
    if (const auto& lens_choice = record.lens_choice) first_score = KnownScoreOf(*lens_choice, lens);
    std::vector<std::optional<FoldCandidate>> candidates{FoldCandidate{guess, fit_options, views.poses}};
    for (size_t k = 1; k < kProfileCandidates.size(); ++k)
      candidates.push_back(rim_candidate(lens, kProfileCandidates[k], views.detections, &warnings));
    const NamedChoice& choice = *(record.profile_choice = ChooseByHeldOutFolds(
                                      kProfileCandidates, candidates, kProfileScoreTolerance, input.target,
                                      views.detections, options.threads, "profile", options.progress, {first_score}));
    start_from_chosen(choice, candidates);
    const bool scored = choice.AnyScored();
    profile_said = choice.chosen + " mirror" + (scored ? " (chosen by held-out folds)" : "");
    record.start = "rim circle, " + profile_said + ", " + lens_said;
    if (!scored)
      warnings.push_back({WarningCode::kProfileNotChosen, "profile",
                          "neither mirror family could be fitted to every held-out fold of the views (a view where "
                          "no other reaches, or no valid sensor?); the " + choice.chosen + " is kept"});
  }
  // A pinhole's tangential terms by held-out folds, from the start the lens and mirror
  // choices left (calib/tangential_choice.h). Held, that start is the last choice's chosen
  // candidate: its score is reused (5 fits fewer).
  const bool choose_tangential =
      options.tangential == kChooseTangential || (tangential_by_default && foldable && !HoldsTangential(options.fixed));
  // A term switched on or not, by held-out folds: off is the last choice's chosen candidate
  // (the current fit options), its score reused where a choice ran.
  auto choose_switch = [&](const std::vector<std::string>& names, FitOptions switched_on, double tolerance,
                           const std::string& stage) {
    std::optional<KnownScore> off_score;
    if (const auto& tangential = record.tangential_choice)
      off_score = KnownScoreOf(*tangential, tangential->chosen);
    else if (const auto& profile = record.profile_choice)
      off_score = KnownScoreOf(*profile, profile->chosen);
    else if (const auto& lens = record.lens_choice)
      off_score = KnownScoreOf(*lens, lens->chosen);
    return ChooseByHeldOutFolds(
        names,
        {FoldCandidate{guess, fit_options, views.poses}, FoldCandidate{guess, std::move(switched_on), views.poses}},
        tolerance, input.target, views.detections, options.threads, stage, options.progress, {off_score, std::nullopt});
  };
  if (choose_tangential && std::string(guess.lens_name()) == "pinhole") {
    FitOptions fitted = fit_options;
    fitted.refine.tangential = true;
    const NamedChoice& choice = *(record.tangential_choice = choose_switch(kTangentialCandidates, std::move(fitted),
                                                                           kTangentialScoreTolerance, "tangential"));
    fit_options.refine.tangential = choice.chosen == kTangentialCandidates[1];
    if (!choice.AnyScored() && !tangential_by_default)
      warnings.push_back({WarningCode::kTangentialNotFitted, "tangential",
                          "neither held nor fitted p1, p2 could be fitted to every held-out fold of the views; they "
                          "are held"});
  }
  // The board's relief by held-out folds, last, from what the choices above left
  // (calib/relief_choice.h).
  const bool choose_relief = options.board_warp && (options.board_relief == kChooseRelief ||
                                                    (!input.guess && options.board_relief.empty() && foldable));
  if (choose_relief) {
    FitOptions relief = fit_options;
    relief.fit_board_relief = true;
    record.relief_choice = choose_switch(kReliefCandidates, std::move(relief), kReliefScoreTolerance, "board relief");
    fit_options.fit_board_relief = record.relief_choice->chosen == kReliefCandidates[1];
  }
  std::optional<Sensor> refit_start;  // the previous pass's fit, where the last fit started
  FitResult fit = FitSensor(guess, input.target, views.detections, views.poses, fit_options);
  // Boards of another size than the target (a decoy the detector accepted, e.g. a window
  // of tiles that passed the continuation test) are refused through the fitted sensor (a
  // suspect through a fit without it) and the fit is repeated without them
  // (calib/board_size_screen.h).
  // Only through a design: from the rim circle alone the sensor's scale is a gauge and its
  // mirror family an approximation, and boards fit a little better at other sizes (on
  // rendered/ohte-sph-misaligned-near 3-4 of 8 true boards were refused that way).
  // Screened again after each refit without refused boards: a second decoy, checked
  // through a sensor the first one bent, may only show once that one is gone. At most a
  // quarter of the views go: a true board checked through a fit without it can fit best
  // at another size too (0.60 x with a giant still in), and a set that is mostly
  // decoys is no calibration set; past that the screen stops with a warning.
  // Screened after the first fit too: the second detection pass refines the corners
  // through that fit, and its refits start there. A decoy refused only after it (a 3.8 x
  // giant among the realistic aprilgrid render's 12 views) had moved fx and m by 0.9 and
  // 0.8 std from the fit without its image.
  const size_t max_refused = std::max<size_t>(1, views.detections.images.size() / 4);
  size_t refused_so_far = 0;
  bool screen_stopped = false;
  std::set<std::string> refused_images;  // kept out of later detection passes
  auto screen_and_refit = [&](const Sensor& start) {
    while (fit.sensor && input.guess && !screen_stopped) {
      BoardSizeScreenOptions screen_options;
      screen_options.threads = options.threads;
      // Through a flat board: the board's warp, shared by every view, bends towards a
      // decoy's size as the sensor does (a 4 x giant among 8 views was no longer refused
      // with the warp free: the fit went 6.5 tolerances off in m and past a valid sphere).
      FitOptions flat_options = fit_options;
      flat_options.fit_board_warp = flat_options.fit_board_relief = false;
      flat_options.compute_covariance = false;  // the screen reads the poses and sigma only
      flat_options.progress = nullptr;
      FitResult flat;
      if (fit_options.fit_board_warp) flat = FitSensor(start, input.target, views.detections, views.poses, flat_options);
      const bool through_flat = flat.sensor.has_value();  // else (no warp, or that fit failed) the fit itself
      const BoardSizeScreen screen = ScreenBoardSizes(start, input.target, views.detections, through_flat ? flat : fit,
                                                      through_flat ? flat_options : fit_options, screen_options);
      const std::vector<size_t>& refused = screen.refused;
      if (refused.empty()) return;
      if (refused_so_far + refused.size() > max_refused) {
        std::string names;
        for (size_t v : refused) names += (names.empty() ? "" : ", ") + views.detections.images[v].image;
        warnings.push_back({WarningCode::kBoardScreenStopped, "",
                            "the board-size check would refuse " + std::to_string(refused_so_far + refused.size()) +
                                " of " + std::to_string(views.detections.images.size() + refused_so_far) +
                                " views (at most a quarter go): kept " + names +
                                "; the sensor may fit them badly (a wrong guess?)"});
        screen_stopped = true;
        return;
      }
      refused_so_far += refused.size();
      for (size_t v : refused) {
        record.views_left_out[views.detections.images[v].image] = "the board " + screen.checks[v].reason;
        refused_images.insert(views.detections.images[v].image);
      }
      for (auto v = refused.rbegin(); v != refused.rend(); ++v) {
        views.observations -= static_cast<int>(views.detections.images[*v].corners.size());
        views.detections.images.erase(views.detections.images.begin() + *v);
        views.poses.erase(views.poses.begin() + *v);
      }
      if (views.detections.images.size() < 3)
        throw InputError(InputMessage(input.source, "images",
                                      std::to_string(views.detections.images.size()) +
                                          " views are left once the boards of another size are refused (need >= 3)"));
      fit = FitSensor(start, input.target, views.detections, views.poses, fit_options);
    }
  };
  screen_and_refit(guess);
  // Second detection pass, from images. Aprilgrids: the corners are refined in patches
  // through a sensor, and a tag's straight edges are straight there only as far as that
  // sensor is right. Through the design guess the patch edges bend, and the corners
  // carried a radius-dependent bias the mirror's size absorbed; re-detected through the
  // first fit they do not (30-view render: A 6 std off after one pass, 0.5 std after two;
  // tests/cli/calibrate_render_test.sh). Each pass fits the tags whole through the previous
  // fit, and the tags at the rim across it. A third pass (opt-in) fits them through a
  // sensor that saw the rim's corners, which the first did not: over 6 re-rendered
  // realistic seeds used 98.57 -> 98.84 %, fx's error no better (8.0 -> 9.0 px RMS;
  // tests/bench/realistic_seeds.py), for a pass's time. Checkerboards: the images where none was found
  // are searched again through the fit's virtual views (calib/detect.h), and every
  // corner, found unrefined, is refined in patches through the fit (on grid steps of 20 px
  // and more, calib/refine_corners.h); a pass after the second only if it or the one
  // before finds more boards. Through the design guess instead, the realistic checkerboard render's fx, k2
  // and decenter_x came out 3.2-4.8 std off (through the first fit: all within 2.2 std).
  const bool checkerboard = input.target.type() == CalibrationTarget::Type::kCheckerboard;
  DetectionSet found = detections;  // checkerboards: the corners as found, not yet refined
  int passes_run = 1;
  int last_pass = options.detection_passes;
  bool boards_found_before = false;  // by the previous pass: refined through a fit that had not seen them
  for (int pass = 2; from_images && pass <= last_pass && fit.sensor; ++pass) {
    // Detected through the previous fit with its rim where the images show it
    // (calib/rim_circle.h): the tags and junctions the rim cuts are fitted across it.
    std::string rim_refused;
    std::optional<Sensor> through =
        rim ? SensorWithImageRim(*fit.sensor, *rim, &rim_refused, /*rim_from_corners=*/!input.guess) : std::nullopt;
    if (!through) through = *fit.sensor;
    const bool boards_found = checkerboard && FindMissedCheckerboards(input, options, *through, &found);
    if (checkerboard && !boards_found && !boards_found_before && pass > 2) break;
    // Boards the last pass asked for found were refined through a fit that had not seen them
    // (theirs an extrapolation where they lie by the rim): one pass more refines and completes
    // them through the fit that has. Realistic checkerboard render, no guess: 553 -> 570 of
    // 570 corners, 0.069 -> 0.013 px from the true sensor at 300 mm, 0.31 -> 0.030 at 2 m over
    // the detected field (the rim boards' corners had bent the fit into the dolly-zoom
    // valley: m 130 mm, true 180).
    if (boards_found && pass == options.detection_passes) ++last_pass;
    boards_found_before = boards_found;
    // Said of a pass whose corners are kept (after the break above), once.
    if (!rim_refused.empty() &&
        std::none_of(warnings.begin(), warnings.end(), [](const CalibrationWarning& w) { return w.code == WarningCode::kImageRimNotUsed; }))
      warnings.push_back({WarningCode::kImageRimNotUsed, "rim_circle",
                          rim_refused + "; detection pass " + std::to_string(pass) +
                              " looked through the fit's own rim (tags or junctions the rim cuts may be lost)"});
    refit_start = *fit.sensor;
    passes_run = pass;
    // The corners a fitted board lacks are predicted through this pass's start (the
    // previous fit) and kept where a junction is there (calib/checkerboard_completion.h).
    if (checkerboard) {
      detections = CornersRefinedThrough(
          input, options, *through, WarpOf(fit, fit_options),
          WithPredictedCheckerCorners(input.target, *through, WarpOf(fit, fit_options), views.detections, fit, found));
    } else {
      // Every pass fits the tags whole, and the tags the rim cuts across it, from their
      // corners predicted through the previous fit (calib/checkerboard_completion.h).
      const DetectionSet raw = FindCorners(input, options, through, false, true, /*refine=*/false).detections;
      detections = CornersRefinedThrough(
          input, options, *through, WarpOf(fit, fit_options),
          WithPredictedTagCorners(input.target, *through, WarpOf(fit, fit_options), views.detections, fit, raw));
    }
    // The skipped views are named again by this pass's ViewsForFit.
    warnings.erase(std::remove_if(warnings.begin(), warnings.end(),
                                  [](const CalibrationWarning& w) { return w.code == WarningCode::kViewSkipped; }),
                   warnings.end());
    // Boards refused so far stay out (their corners stay in `detections`: every corner found).
    views = ViewsForFit(*refit_start, input, FittableCorners(input, WithoutImages(detections, refused_images), &unrefined),
                        &warnings);
    held = SplitOff(&views, holdout_names);
    AddViewNames(held, &ever_held);
    fit = FitSensor(*refit_start, input.target, views.detections, views.poses, fit_options);
  }
  CheckHeldOutNamesUsable(input, options.holdout_images, ever_held);
  Sensor fit_start = refit_start ? *refit_start : guess;
  // The corners changed: screened again, afresh if the first screen stopped (its pass-1
  // corners came through the design guess, and their warning no longer applies).
  if (passes_run > 1) {
    screen_stopped = false;
    warnings.erase(std::remove_if(warnings.begin(), warnings.end(),
                                  [](const CalibrationWarning& w) { return w.code == WarningCode::kBoardScreenStopped; }),
                   warnings.end());
    screen_and_refit(fit_start);
  }
  // The spline's knot count by held-out folds over the views the fit kept, then the fit
  // again with that count. Without a guess or a family asked for, the spline is the last
  // family candidate: a count or none (the family chosen) by the same folds. On real sets
  // (docs/calibrate.md) it keeps the polynomial on the Mei set, takes 4 knots on the
  // OCamCalib VMR set (held out 0.302 px against 0.305) and 16 on its KaidanOmni, whose
  // inner ring no polynomial follows (0.210 against 0.343). Only through the orthographic
  // lens: through the pinhole the spline's free offset over the seen ring slides with the
  // focal length (the dolly zoom m's hold closes; docs/calibrate.md).
  // The views the fit kept (the folds' views): after the passes, some may be left out.
  const int kept_view_count =
      fit.sensor ? static_cast<int>(std::count_if(fit.view_left_out.begin(), fit.view_left_out.end(),
                                                  [](const std::string& why) { return why.empty(); }))
                 : 0;
  const bool knots_by_default = profile_unset_or_auto && options.knots == 0 && !folds_knots &&
                                kept_view_count >= kMinViewsForFolds &&
                                std::string(fit_start.lens_name()) == "orthographic";
  std::string knot_fallback;  // why the fitted count is not the folds' choice
  std::optional<KnotChoice> knot_choice;
  // Without a spline: the guess's family, the family chosen, or the polynomial the rim
  // circle starts a spline from.
  const std::string guess_profile = input.guess ? input.guess->profile_name() : fit_start.profile_name();
  const std::string base = guess_profile == "spline" ? "polynomial" : guess_profile;
  if ((options.knots == kChooseKnots || knots_by_default) && fit.sensor) {
    DetectionSet kept_views = views.detections;
    kept_views.images.clear();
    std::vector<TargetPose> kept_poses;
    for (size_t v = 0; v < views.detections.images.size(); ++v)
      if (fit.view_left_out[v].empty())
        kept_views.images.push_back(views.detections.images[v]), kept_poses.push_back(views.poses[v]);
    try {
      knot_choice = ChooseKnots(fit_start, base, input.target, kept_views, kept_poses, fit_options, options.progress);
    } catch (const InputError& error) {
      if (!knots_by_default) throw;  // asked for: said, as the family and lens choices cannot be
      warnings.push_back({WarningCode::kProfileNotChosen, "knots",
                          std::string(error.what()) + "; the " + base + " mirror is kept"});
    }
  } else if (folds_knots && fit.sensor) {  // a held-out fold: the full set's count, the only candidate
    knot_choice = KnotChoice{base, {*folds_knots}, {0.0}, 0, 0, *folds_knots};
  }
  if (knot_choice) {
    KnotChoice& choice = *knot_choice;
    const int folds_choice = choice.chosen;
    ValidKnotFit chosen_fit = FitValidKnotCount(choice, base, [&](int knots) {
      // The family the fit already has (the default's "no spline"): that fit, not again.
      if (knots == 0 && base == fit_start.profile_name()) return KnotCountFit{fit, fit_start};
      Sensor start = knots > 0 ? ConvertProfile(fit_start, "spline", knots) : ConvertProfile(fit_start, base);
      FitResult result = FitSensor(start, input.target, views.detections, views.poses, WithShapeOf(fit_options, start));
      return KnotCountFit{std::move(result), std::move(start)};
    });
    if (chosen_fit.fitted) {
      fit = std::move(chosen_fit.fitted->fit), fit_start = std::move(chosen_fit.fitted->start);
      choice.chosen = chosen_fit.knots;
    } else if (chosen_fit.failed) {
      fit = std::move(*chosen_fit.failed);  // no sensor: "the fit failed" below
    }
    fit_options = WithShapeOf(fit_options, fit_start);
    const int chosen = choice.chosen;
    if (!folds_knots) record.knot_choice = choice;  // a fold's stand-in choice is not reported
    const bool default_choice = knots_by_default || folds_knots;
    record.start += chosen > 0 ? ", " + std::to_string(chosen) + " knots"
                    : default_choice ? ", no spline"
                                     : ", the " + base + " mirror";
    record.start += folds_knots ? " (the full set's)"
                    : chosen == folds_choice ? " (chosen by held-out folds)"
                                             : " (held-out folds' next choice)";
    knot_fallback = chosen_fit.replaced;
  }
  const DetectionSet& usable = views.detections;
  if (!fit.sensor) throw InputError(InputMessage(input.source, "", "the fit failed: " + fit.solver_report));
  const std::string why_invalid = ValidateSensorModel(fit.sensor->model());

  record.rms_px = fit.rms_px;
  record.rms_all_px = AllCornerRms(fit);
  record.board_warp = fit.board_warp;
  record.converged = fit.converged;
  record.outliers = fit.outliers;
  record.dropped = fit.dropped;
  record.unrefined_corners_left_out = unrefined;
  record.observations = fit.observations;
  record.solver_report = fit.solver_report;
  record.fixed_blocks = fit_options.refine.HeldNames();
  record.robust_loss_px = fit_options.robust_loss_px;
  record.covariance_ok = fit.covariance_ok;
  record.detection_passes = passes_run;
  if (options.leave_one_out) record.leave_one_out = LeaveOneOut(fit_start, input, views, fit_options, options.progress);
  if (!why_invalid.empty())
    warnings.push_back({WarningCode::kSensorInvalid, "", "the fitted sensor fails validation: " + why_invalid});
  if (!knot_fallback.empty()) warnings.push_back({WarningCode::kKnotCountReplaced, "knots", knot_fallback});
  if (!fit.converged) warnings.push_back({WarningCode::kNotConverged, "", "the solver did not converge: " + fit.solver_report});
  if (!fit.covariance_ok)
    warnings.push_back({WarningCode::kFreeGauge, "",
                        "the parameters are not all determined by the data (a free gauge): fix one with --fix"});
  // Trust from the covariance (calib/fit_covariance.h): weakly determined scale-like
  // parameters, named with the one they trade off with; the dolly-zoom block's condition.
  std::vector<CovarianceParameter> free_parameters;
  for (const ParameterEstimate& p : fit.parameters)
    if (!p.fixed && std::isfinite(p.std)) free_parameters.push_back({p.name, p.value, p.group, p.scale_like});
  if (fit.covariance_ok && free_parameters.size() == fit.covariance_names.size()) {
    record.scale_block_condition = ScaleBlockCondition(free_parameters, fit.covariance);
    for (const CovarianceFinding& weak : WeakParameters(free_parameters, fit.covariance))
      warnings.push_back({WarningCode::kWeaklyDetermined, weak.parameter, weak.text});
  }
  if (std::isfinite(fit.vertex_curvature_std_ratio)) {
    char text[400];
    std::snprintf(text, sizeof text,
                  "c1 is weakly determined (std %.1f%% of its value): few corners reflect inside the spline's first "
                  "two knot spacings, and past them its knots reproduce c1 r^2; the other parameters' stds and the "
                  "predicted error hold it at its fitted value (views nearer the mirror's axis would determine it)",
                  100.0 * fit.vertex_curvature_std_ratio);
    warnings.push_back({WarningCode::kWeaklyDetermined, "c1", text});
  }
  // One distance: a non-central mirror's shape shows in how its image changes with the
  // object's distance (the viewpoints slide), so with every board at about the same range
  // the shape trades off against m and the lens scale.
  const bool shape_free = std::any_of(fit.parameters.begin(), fit.parameters.end(),
                                      [&](const ParameterEstimate& p) { return !p.fixed && p.group == ParameterGroup::kShape; });
  double nearest_mm = HUGE_VAL, farthest_mm = 0.0;
  for (size_t v = 0; v < fit.poses.size(); ++v) {
    if (!fit.view_left_out[v].empty()) continue;  // its pose was not fitted
    nearest_mm = std::min(nearest_mm, fit.poses[v].camera_from_target_translation_mm.norm());
    farthest_mm = std::max(farthest_mm, fit.poses[v].camera_from_target_translation_mm.norm());
  }
  record.nearest_target_mm = nearest_mm, record.farthest_target_mm = farthest_mm;
  if (shape_free && farthest_mm < kOneDistanceRatio * nearest_mm) {
    char text[300];
    std::snprintf(text, sizeof text,
                  "all targets are at one distance (%.0f-%.0f mm from the lens) while the mirror shape is free: the shape "
                  "is weakly determined; add views at least %.1fx nearer or farther, or fix it (--fix shape)",
                  nearest_mm, farthest_mm, kOneDistanceRatio);
    warnings.push_back({WarningCode::kOneDistance, "", text});
  }
  // Views the fit left out, and why (their corners are in the report, marked dropped;
  // those of boards of another size are not in the report).
  for (const auto& [image, why] : record.views_left_out)
    warnings.push_back({WarningCode::kViewLeftOut, image, image + ": view left out of the fit: " + why});
  for (size_t v = 0; v < usable.images.size(); ++v)
    if (!fit.view_left_out[v].empty()) {
      warnings.push_back({WarningCode::kViewLeftOut, usable.images[v].image,
                          usable.images[v].image + ": view left out of the fit: " + fit.view_left_out[v]});
      record.views_left_out[usable.images[v].image] = fit.view_left_out[v];
    }
  for (const std::string& conflict : fit.tolerance_conflicts) warnings.push_back({WarningCode::kToleranceConflict, "", conflict});
  for (const std::string& note : fit.tolerance_notes) warnings.push_back({WarningCode::kToleranceNote, "", note});
  record.outlier_threshold_px = fit.outlier_threshold_px;
  for (size_t v = 0; v < usable.images.size(); ++v) record.per_view_outliers[usable.images[v].image] = fit.per_view_outliers[v];
  record.sigma_px = fit.sigma_px;
  record.tolerances = fit_options.tolerances;
  record.guess_rim_radius_mm = design_rim_mm;
  record.fitted_rim_radius_mm = fit.sensor->rim_radius_mm();
  if (fit.covariance_ok) record.covariance_names = fit.covariance_names, record.covariance = fit.covariance;

  DetectionSet fitted_views = usable;  // the field the fit saw: its fitted views
  fitted_views.images.clear();
  std::vector<TargetPose> fitted_start_poses;  // their starting poses
  for (size_t v = 0; v < usable.images.size(); ++v)
    if (fit.view_left_out[v].empty())
      fitted_views.images.push_back(usable.images[v]), fitted_start_poses.push_back(views.poses[v]);
  const std::vector<Eigen::Vector2d> field =
      FieldPixels(*fit.sensor, FieldOfCorners(*fit.sensor, fitted_views), options.predicted_error_step_px);
  const double rim_mm = design_rim_mm;

  // Generalisation (calib/cross_validation.h): held-out views through the fitted sensor;
  // two halves' calibrations compared where the user looks.
  if (!holdout_names.empty()) {
    ProgressReporter progress(options.progress, "holdout", 1);
    FitOptions held_options = fit_options;
    if (fit.board_warp) held_options.board_warp = fit.board_warp->warp;
    record.holdout = EvaluateHeldOutViews(*fit.sensor, input.target, held.detections, held_options);
    progress.Step();
    for (const auto& [image, why] : record.holdout->not_evaluated)
      warnings.push_back({WarningCode::kViewLeftOut, image, image + ": held-out view not evaluated: " + why});
    WarnIfHeldOutWorse("the " + std::to_string(record.holdout->images.size()) + " held-out views fit at",
                       record.holdout->rms_px, record.rms_all_px, &warnings);
  }
  // Where the boards were: the predicted error's and the halves' one rigid alignment is
  // fitted there (calib/predicted_error.h); NaN (no corner projects): per distance.
  const double boards_median_mm = MedianCornerDistanceMm(*fit.sensor, input.target, usable, fit);
  if (options.cross_validate) {
    double distance_mm = options.cross_validation_distance_mm;
    if (!(distance_mm > 0.0)) distance_mm = !options.distances_mm.empty()   ? options.distances_mm.front()
                                            : !options.distances_n.empty() ? options.distances_n.front() * rim_mm
                                                                           : kDefaultCrossValidationDistanceMm;
    ProgressReporter progress(options.progress, "cross-validation", 1);
    TwoHalves halves = CrossValidateHalves(fit_start, input.target, fitted_views, fitted_start_poses, fit_options,
                                           field, distance_mm, boards_median_mm);
    progress.Step();
    record.cross_validation = CalibrationRecord::CrossValidationRecord{
        halves.images, halves.rms_px, std::move(halves.diff), std::move(halves.diff_aligned_at_boards)};
  }

  // The error at the user's distances: the covariance through the projection over the
  // observed field (calib/predicted_error.h). Default: the corners' median distance from
  // their reflection points, and infinity.
  if (fit.covariance_ok) {
    std::vector<double> distances = options.distances_mm;
    for (double n : options.distances_n) distances.push_back(n * rim_mm);
    if (distances.empty()) {
      if (std::isfinite(boards_median_mm)) distances.push_back(boards_median_mm);
      distances.push_back(kInfinityMm);
    }
    predicted = PredictProjectionError(*fit.sensor, fit, field, distances, boards_median_mm);
    for (const PredictedError& map : predicted) {
      const bool infinite = map.distance_mm >= kInfinityMm;
      char label[80];
      if (infinite) {
        std::snprintf(label, sizeof label, "infinity");
      } else {
        std::snprintf(label, sizeof label, "%.0f mm (n = %.2f)", map.distance_mm, map.distance_mm / rim_mm);
      }
      distance_labels.push_back(label);
      record.predicted_error.push_back({map.distance_mm, infinite ? HUGE_VAL : map.distance_mm / rim_mm, map.median_px, map.max_px,
                                        static_cast<int>(map.pixels.size()), map.unpredicted,
                                        map.in_camera_frame_median_px, map.in_camera_frame_max_px,
                                        map.aligned_once ? map.aligned_at_mm : NAN});
      if (!std::isfinite(map.max_px))
        warnings.push_back({WarningCode::kPredictedErrorUnknown, "",
                            std::string("the projection error at ") + label + " could not be predicted (no field pixel projects)"});
      if (map.max_px > options.max_predicted_error_px) {
        // What would help: the valleys the data leave open (docs/calibrate.md "When the
        // predicted error warning fires").
        std::vector<std::string> help;
        if (farthest_mm < kOneDistanceRatio * nearest_mm) help.push_back("boards at other distances");
        const bool distortion_free = std::any_of(fit.parameters.begin(), fit.parameters.end(), [](const ParameterEstimate& p) {
          return p.group == ParameterGroup::kDistortion && !p.fixed;
        });
        if (distortion_free) help.push_back("the distortion held (--fix distortion)");
        if (fit_options.tolerances.empty()) help.push_back("design tolerances (--tolerance)");
        help.push_back("more views over the whole field");
        std::string joined;
        for (size_t k = 0; k < help.size(); ++k) joined += (k ? (k + 1 == help.size() ? " or " : ", ") : "") + help[k];
        char text[400];
        std::snprintf(text, sizeof text,
                      "predicted projection error up to %.2f px (median %.2f) at %s exceeds %.2f px: the calibration "
                      "may misplace objects there, one against another, by that much; %s would help",
                      map.max_px, map.median_px, label, options.max_predicted_error_px, joined.c_str());
        warnings.push_back({WarningCode::kPredictedErrorHigh, "", text});
      }
    }
  }
  for (const CalibrationWarning& w : warnings) {
    const bool skipped = w.code == WarningCode::kViewSkipped || w.code == WarningCode::kImageUnreadable ||
                         w.code == WarningCode::kImageSizeDiffers;
    if (skipped) {
      record.views_skipped[w.subject] = w.reason;
    } else if (w.code != WarningCode::kCheckerboardRefused) {
      record.warnings.push_back(w.text);
    }
  }
  for (size_t v = 0; v < usable.images.size(); ++v) record.per_view_rms_px[usable.images[v].image] = fit.per_view_rms_px[v];
  for (size_t v = 0; v < fit.per_view_weight.size(); ++v) record.per_view_weight[usable.images[v].image] = fit.per_view_weight[v];
  record.parameters = fit.parameters;
  for (size_t v = 0; v < usable.images.size(); ++v)
    if (fit.view_left_out[v].empty()) record.poses[usable.images[v].image] = fit.poses[v];

  const Sensor fitted = *fit.sensor;
  return CalibrationResult{fitted,
                           std::move(record),
                           std::move(fit),
                           from_images ? std::move(detections) : DetectionSet(),
                           std::move(views.detections),
                           std::move(predicted),
                           std::move(distance_labels),
                           std::move(warnings)};
}

}  // namespace

CalibrationResult Calibrate(const CalibrationInput& input, const CalibrationOptions& options) {
  if (const std::string why = options.Check(); !why.empty()) throw InputError(why);
  if (options.holdout_folds > 0) return CalibrateWithHeldOutFolds(input, options);
  return CalibrateOnce(input, options, nullptr, nullptr);
}

}  // namespace omnical

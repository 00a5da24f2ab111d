// The calibration pipeline as one call: corners (detected here from images, or given),
// the starting sensor (a guess, converted to another mirror family if asked, or the
// mirror's rim circle), the checks that the views can determine the sensor, the robust
// staged bundle fit, a second detection pass through the first fit (aprilgrid from
// images), boards of the wrong size refused, optionally leave-one-out, the predicted
// projection error at the user's distances, and every warning as a typed code plus text.
// No printing and no files written: calibration_json.h writes (and reads back) the record,
// calib/report/ the figures.
#pragma once

#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "calib/bundle_fit.h"
#include "calib/calibration_record.h"
#include "calib/calibration_warning.h"
#include "calib/design_tolerances.h"
#include "calib/image_detection.h"
#include "calib/initial_sensor.h"
#include "calib/knot_choice.h"
#include "calib/predicted_error.h"
#include "calib/profile_choice.h"
#include "calib/relief_choice.h"
#include "calib/tangential_choice.h"
#include "calib/target.h"
#include "model/progress.h"
#include "model/sensor.h"

namespace omnical {

struct CalibrationInput {
  CalibrationTarget target;
  std::string target_name;  // the spec file (detections refer to it; messages name it)
  // The corners: exactly one of image files (detected here), images in memory, or detections.
  std::vector<std::string> image_paths;
  std::vector<NamedImage> images;
  std::optional<DetectionSet> detections;
  std::string source;  // what the corners came from, named in messages (a directory, a file)
  // The starting sensor: a guess with its design tolerances, or none (the rim circle).
  std::optional<Sensor> guess;
  std::string guess_name;  // its file, named in messages and in the record's "start"
  DesignTolerances guess_tolerances;
};

struct CalibrationOptions {
  // Mirror family to fit: "" the guess's; without a guess kChooseProfile (the polynomial or
  // the even asphere by held-out folds, calib/profile_choice.h) where the usable views allow
  // folds, else the polynomial. kChooseProfile only without a guess. The folds of
  // holdout_folds keep the family the full set used.
  std::string profile;
  double rim_field_deg = kDefaultRimFieldDeg;
  // Without a guess, the lens the rim circle starts (calib/initial_sensor.h):
  // "orthographic" (a telecentric lens), "pinhole" (a perspective camera in front of the
  // mirror; with a free-form mirror its distance m and the mirror's decenter are held,
  // the gauges the free shape leaves: m trades with the focal length like a dolly zoom,
  // decenter with the principal point and tilt; k1, k2 are held as for any free-form
  // mirror), or kChooseLens: the one whose fits predict held-out folds of the views better
  // (calib/lens_choice.h), the orthographic unless the pinhole does by more than 1 %.
  // "" (the default): kChooseLens where the usable views allow folds
  // (kMinViewsForFolds), else the orthographic. The folds of holdout_folds keep the lens
  // the full set used. With a guess: "" (the guess's lens).
  std::string lens;
  // A pinhole's tangential distortion p1, p2 (calib/tangential_choice.h): "off" held at
  // the start's values, "on" fitted, or kChooseTangential: fitted where that predicts
  // held-out folds of the views better by more than 1 %. Refused with an orthographic lens;
  // where the lens is chosen, applied only if the pinhole is. "" (the default): without a
  // guess kChooseTangential where the views allow folds and `fixed` does not hold p1, p2
  // (said in no warning where the orthographic lens is chosen), else "off". The folds of
  // holdout_folds keep the choice.
  std::string tangential;
  std::set<std::string> fixed;  // blocks held, by RefineOptions::Hold's names (calib/fit_options.h)
  double loss_px = 1.0;
  int max_iterations = 200;
  // From images: 2 re-detects through the first fit, 3 through the second (checkerboards:
  // only where it or the one before finds more boards). Boards a checkerboard's last pass
  // found get one pass more (record.detection_passes counts the passes run).
  int detection_passes = 2;
  int threads = 1;  // detection, the board-size checks and the fit's Jacobians (the same result for any count)
  bool leave_one_out = false;
  // Generalisation (calib/cross_validation.h): views kept out of the fit (spread evenly
  // over the input) and evaluated with the sensor held; the usable views split in two
  // halves, each calibrated, compared at cross_validation_distance_mm (0: the first of
  // distances_mm / distances_n, else 2 m).
  int holdout_views = 0;
  // The views to keep out by name instead (each a usable view); the folds below set it.
  std::set<std::string> holdout_images;
  // Every view held out once, K = holdout_folds at a time: after the full set's calibration
  // (the one written), F = ceil(N / K) more over the N usable views, fold f keeping out views
  // f, f + F, f + 2F, ... of them; record.holdout_folds pools them. One split of a few views
  // is too few to judge by: on the real dev set the five splits of two views had held-out /
  // training ratios of 0.83-1.42, pooled 1.09 (docs/calibrate.md). Not with holdout_views.
  // The folds reuse the full set's first detection pass (no fold changes it).
  int holdout_folds = 0;
  // Fit the board's out-of-plane warp (calib/board_warp.h) with the sensor. On by default,
  // as mrcal fits its calobject_warp: hand-held paper bends, and a flat board costs two
  // parameters found ~0 (docs/calibrate.md, "Bent boards").
  bool board_warp = true;
  // The board's relief (calib/relief_choice.h: each corner's own out-of-plane offset on
  // top of the warp, shared by every view): "off", "on" (fitted) or kChooseRelief: fitted
  // where that predicts held-out folds of the views better by more than 1 %. "" (the
  // default): without a guess kChooseRelief where the views allow folds, else "off". Needs
  // board_warp. The folds of holdout_folds keep the choice.
  std::string board_relief;
  // Weight each view's corners by its own noise (FitOptions::view_noise_weights).
  bool view_weights = false;
  // How a checkerboard's corners are refined through the first fit (second detection pass).
  // Unset: by their edges, every one (CheckerRefinement::kEdges, calib/refine_corners.h),
  // wherever that applies (a checkerboard's images, two passes or more). Set, it is refused
  // where it cannot apply. true: by the edges. false: cornerSubPix on grid steps of 20 px and more,
  // OpenCV's corners on the rest (the default before: those sat 0.02-0.11 px inwards per
  // view on the realistic renders and put parameters beyond 3 std on 6 of 6 re-rendered
  // seeds; docs/calibrate.md, "Checkerboard corners by their edges").
  std::optional<bool> checkerboard_edges;
  // A spline mirror's knot count (model/spline_profile.h): 0 keeps the guess's (6 when
  // converted), 4..16, or kChooseKnots: chosen by held-out folds (calib/knot_choice.h).
  int knots = 0;
  bool cross_validate = false;
  double cross_validation_distance_mm = 0.0;
  DesignTolerances tolerances;  // added to / overriding the guess's
  std::vector<double> distances_mm, distances_n;  // for the predicted error (n: design rim radii)
  double max_predicted_error_px = 0.3;
  double predicted_error_step_px = 16.0;  // grid of the predicted-error maps
  ProgressCallback progress;
  std::string Check() const;  // "" or "field: problem"
};

struct CalibrationResult {
  Sensor sensor;               // the fitted sensor
  CalibrationRecord record;    // what calibration.json holds (calibration_json.h)
  FitResult fit;               // per corner residuals, for the report
  DetectionSet detections;     // every detected corner (empty when detections were given)
  DetectionSet views;          // the views given to the fit, in FitResult's order (see fit.view_left_out)
  std::vector<PredictedError> predicted;  // one map per distance
  std::vector<std::string> distance_labels;
  std::vector<CalibrationWarning> warnings;  // detection's and the fit's, in order
};

// Throws InputError naming the field or input that cannot work (too few views, one pose,
// image size, a failed fit), Cancelled if the progress callback asked to stop.
CalibrationResult Calibrate(const CalibrationInput& input, const CalibrationOptions& options);

}  // namespace omnical

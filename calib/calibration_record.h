// What a calibration run reports, exactly as calibration.json holds it: written by
// WriteCalibrationJson and read back by ReadCalibrationJson (calib/calibration_json.h).
// The fitted sensor itself is in sensor.yaml.
#pragma once

#include <Eigen/Core>

#include <cmath>
#include <array>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "calib/bundle_fit.h"
#include "calib/cross_validation.h"
#include "calib/design_tolerances.h"
#include "calib/knot_choice.h"
#include "calib/lens_choice.h"

namespace omnical {

struct CalibrationRecord {
  double rms_px = 0.0;  // per corner, sqrt(mean |e|^2), over the inliers
  double rms_all_px = NAN;  // the same over every fitted corner, outliers included
  bool converged = false;
  int outliers = 0, dropped = 0, unrefined_corners_left_out = 0, observations = 0;
  std::string solver_report;
  std::set<std::string> fixed_blocks;
  double robust_loss_px = 0.0;
  bool covariance_ok = false;
  std::string start;  // where the fit started: the guess file, or the rim circle
  int detection_passes = 1;
  struct RimCircleRecord {
    Eigen::Vector2d centre_px = Eigen::Vector2d::Zero();
    double radius_px = 0.0, inlier_fraction = 0.0, rms_px = 0.0;
  };
  std::optional<RimCircleRecord> rim_circle;
  struct Spread {
    double min = 0.0, max = 0.0, std = 0.0;
  };
  std::map<std::string, Spread> leave_one_out;  // per parameter; empty unless asked
  // Views kept out of the fit and evaluated with the sensor held (CalibrationOptions::
  // holdout_views); the training RMS to compare with is rms_all_px / rms_px.
  std::optional<HeldOutViews> holdout;
  std::optional<HeldOutFolds> holdout_folds;  // every view held out once (CalibrationOptions::holdout_folds)
  std::optional<BoardWarpEstimate> board_warp;  // when fitted (CalibrationOptions::board_warp)
  std::optional<KnotChoice> knot_choice;  // when chosen (CalibrationOptions::knots = kChooseKnots)
  // When chosen (CalibrationOptions::lens = kChooseLens, or unset without a guess).
  std::optional<NamedChoice> lens_choice;
  // When chosen (CalibrationOptions::profile = kChooseProfile, or unset without a guess).
  std::optional<NamedChoice> profile_choice;
  // When chosen (CalibrationOptions::tangential = kChooseTangential, or unset without a
  // guess; a pinhole).
  std::optional<NamedChoice> tangential_choice;
  // Whether the board's relief was fitted, chosen by held-out folds (calib/relief_choice.h).
  std::optional<NamedChoice> relief_choice;
  // The two halves' calibrations compared (CalibrationOptions::cross_validate). The diff's
  // per-pixel vectors are kept in memory for the report's figure; the file has the summary.
  struct CrossValidationRecord {
    std::array<std::vector<std::string>, 2> halves;
    std::array<double, 2> half_rms_px{{NAN, NAN}};
    ProjectionDiff diff;
    std::optional<ProjectionDiff> diff_aligned_at_boards;  // calib/cross_validation.h
  };
  std::optional<CrossValidationRecord> cross_validation;
  double nearest_target_mm = 0.0, farthest_target_mm = 0.0;  // fitted views, from the lens
  std::map<std::string, std::string> views_left_out;          // image -> why
  // Images no view was made of (unreadable, another size, no board or too few corners
  // found, no starting pose): image -> why.
  std::map<std::string, std::string> views_skipped;
  double outlier_threshold_px = 0.0;
  std::map<std::string, int> per_view_outliers;  // image -> corners cut
  double sigma_px = 0.0;
  DesignTolerances tolerances;
  double guess_rim_radius_mm = 0.0, fitted_rim_radius_mm = 0.0;
  std::vector<std::string> covariance_names;  // empty unless covariance_ok
  Eigen::MatrixXd covariance;
  // The condition number of the scale-like parameters' correlation matrix (lens focal, m,
  // mirror size: the dolly-zoom valley); NaN without a covariance.
  double scale_block_condition = NAN;
  struct PredictedErrorSummary {
    double distance_mm = 0.0;  // kInfinityMm (predicted_error.h) for infinity
    double n_rim_radii = 0.0;  // distance in the start's rim radii (HUGE_VAL for infinity)
    double median_px = 0.0, max_px = 0.0;  // after the best rigid alignment (calib/predicted_error.h)
    int field_pixels = 0, unpredicted_pixels = 0;
    double in_camera_frame_median_px = NAN, in_camera_frame_max_px = NAN;  // the frame's own uncertainty kept
    // Where the one rigid alignment was fitted (the boards' median distance); NaN: fitted
    // at each distance (files written before 2026-11-29's second change, or too few field
    // pixels project at the boards' distance) or none.
    double aligned_at_mm = NAN;
  };
  std::vector<PredictedErrorSummary> predicted_error;
  std::vector<std::string> warnings;  // the texts (the codes are in CalibrationResult)
  std::map<std::string, double> per_view_rms_px;  // image -> RMS (NaN: left out)
  std::map<std::string, double> per_view_weight;  // image -> noise weight (--view-weights; empty otherwise)
  std::vector<ParameterEstimate> parameters;      // the fit's order (read back: by name)
  std::map<std::string, TargetPose> poses;        // fitted views: image -> camera_from_target
};

}  // namespace omnical

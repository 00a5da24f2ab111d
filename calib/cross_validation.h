// How well a calibration generalises beyond the corners it was fitted to, measured the two
// ways users of this field trust:
// - held-out views (the BabelCalib protocol): views kept out of the fit, their poses fitted
//   with the sensor held; their RMS against the training RMS says whether the model
//   predicts new data or memorised the old (an over-flexible model fits its own corners
//   and misses the next board's).
// - two halves: the views split in two, each half calibrated on its own, and the two
//   sensors compared over the observed field at a distance after the best rigid alignment
//   (calib/projection_diff.h): how far two equally good calibrations disagree where the
//   user will look.
// RMS everywhere is per corner, sqrt(mean |e|^2) over 2-D residual vectors.
#pragma once

#include <array>
#include <cmath>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "calib/bundle_fit.h"
#include "calib/detections.h"
#include "calib/projection_diff.h"
#include "calib/target.h"
#include "model/sensor.h"

namespace omnical {

// `count` indices spread evenly over [0, total): the centres of `count` equal runs, so
// held-out views sample the whole sequence (a hand-held set drifts in distance and angle).
std::vector<size_t> EvenlySpreadIndices(size_t total, size_t count);

// Per-corner RMS over every fitted view's corners with a residual, outliers included.
double AllCornerRms(const FitResult& fit);
// The same over one view's residuals (NaN: none): how a held-out view's RMS is counted
// (outliers are a fit's notion; a held-out view has none).
double AllCornerViewRms(const std::vector<Eigen::Vector2d>& residuals_px);

struct HeldOutViews {
  std::vector<std::string> images;               // held out, in the input's order
  std::map<std::string, double> per_view_rms_px;  // all corners of the view (NaN: no pose)
  std::map<std::string, std::string> not_evaluated;  // image -> why (no pose through the sensor)
  double rms_px = NAN;         // all held-out corners
  double inlier_rms_px = NAN;  // the corners the outlier rule keeps
  int corners = 0, outliers = 0;
  // Detected corners of the posed views with no residual: no ray through the sensor even
  // at its widest valid rim (a score without them flatters the sensor).
  int unscored_corners = 0;
};

// Every view held out once (CalibrationOptions::holdout_folds): one calibration per fold,
// each with the fold's views kept out, evaluated as HeldOutViews; pooled over the folds.
struct HeldOutFolds {
  struct Fold {
    std::vector<std::string> images;  // held out
    double rms_px = NAN;              // their corners, all
    int corners = 0;
    double training_rms_px = NAN;     // the fold's fitted views, all corners
    int training_corners = 0;
  };
  int views_per_fold = 0;
  std::vector<Fold> folds;
  std::map<std::string, double> per_view_rms_px;  // each view, when held out (NaN: no pose)
  double rms_px = NAN;           // every fold's held-out corners
  double training_rms_px = NAN;  // every fold's training corners
  int corners = 0, training_corners = 0;
};

// The views' poses fitted with `sensor` held (robust loss and outlier rule as in
// `options`; every view kept however it fits: a held-out view is a measurement, not a
// suspect). The board's warp is held at options.board_warp (the training fit's).
HeldOutViews EvaluateHeldOutViews(const Sensor& sensor, const CalibrationTarget& target, const DetectionSet& views,
                                  FitOptions options);

struct TwoHalves {
  std::array<std::vector<std::string>, 2> images;  // even and odd positions of the fitted views
  std::array<double, 2> rms_px{{NAN, NAN}};       // each half's own fit, inliers
  std::vector<Sensor> sensors;  // the two halves' fits, in that order
  ProjectionDiff diff;  // sensors[1] against sensors[0], aligned at distance_mm
  // The same with one rigid motion fitted at align_at_mm (the boards' median distance) and
  // carried to distance_mm, as calibrate's predicted error (calib/projection_diff.h);
  // empty without align_at_mm or where too few field pixels project there.
  std::optional<ProjectionDiff> diff_aligned_at_boards;
};

// Each half fitted from `start` (the full fit's start, same options, no covariance), then
// compared over `field_pixels` at distance_mm. Throws InputError when a half has fewer than
// 3 views or its fit fails.
TwoHalves CrossValidateHalves(const Sensor& start, const CalibrationTarget& target, const DetectionSet& views,
                              const std::vector<TargetPose>& initial_poses, FitOptions options,
                              const std::vector<Eigen::Vector2d>& field_pixels, double distance_mm,
                              double align_at_mm = NAN);

}  // namespace omnical

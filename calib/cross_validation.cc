#include "calib/cross_validation.h"

#include <algorithm>
#include <cmath>

#include "model/input_error.h"

namespace omnical {
namespace {

// Sum of squares and count of one view's finite residuals (outliers included).
void AddView(const std::vector<Eigen::Vector2d>& residuals, double* square, int* count) {
  for (const Eigen::Vector2d& e : residuals)
    if (e.allFinite()) *square += e.squaredNorm(), ++*count;
}

}  // namespace

std::vector<size_t> EvenlySpreadIndices(size_t total, size_t count) {
  std::vector<size_t> indices;
  if (total == 0) return indices;
  count = std::min(count, total);
  for (size_t i = 0; i < count; ++i)
    indices.push_back(std::min(total - 1, static_cast<size_t>((i + 0.5) * static_cast<double>(total) / count)));
  return indices;
}

double AllCornerRms(const FitResult& fit) {
  double square = 0.0;
  int count = 0;
  for (size_t v = 0; v < fit.residuals_px.size(); ++v)
    if (v >= fit.view_left_out.size() || fit.view_left_out[v].empty()) AddView(fit.residuals_px[v], &square, &count);
  return count ? std::sqrt(square / count) : NAN;
}

double AllCornerViewRms(const std::vector<Eigen::Vector2d>& residuals_px) {
  double square = 0.0;
  int count = 0;
  AddView(residuals_px, &square, &count);
  return count ? std::sqrt(square / count) : NAN;
}

HeldOutViews EvaluateHeldOutViews(const Sensor& sensor, const CalibrationTarget& target, const DetectionSet& views,
                                  FitOptions options) {
  HeldOutViews held;
  DetectionSet posed = views;
  posed.images.clear();
  std::vector<TargetPose> poses;
  // Posed through the sensor as far as it is valid (up to twice its rim): a fitted rim
  // encloses only the corners it was fitted on, and the model predicts past it. Through the
  // fitted rim the near renders' view near006, by the rim, had too few corners with a ray
  // through the pinhole's fold fits: the pinhole (0.25 px from the true sensor at 300 mm)
  // scored "failed" and the orthographic kept was 2.05 px off. Through 1.15 x that rim (the
  // fit's own allowance) 48 of its 1080 corners still had no residual.
  const Sensor wide = SensorWithWidestValidRim(sensor, 2.0);
  for (const ImageDetections& image : views.images) {
    held.images.push_back(image.image);
    TargetPose pose;
    if (image.corners.size() < 4 || !InitialTargetPose(wide, target, image, &pose)) {
      held.not_evaluated[image.image] = "no pose through the fitted sensor (fewer than 4 usable corners)";
      held.per_view_rms_px[image.image] = NAN;
      continue;
    }
    posed.images.push_back(image);
    poses.push_back(pose);
  }
  if (posed.images.empty()) return held;
  options.refine = RefineOptions::PosesOnly();
  options.tolerances.clear();
  options.design.clear();
  options.compute_covariance = false;
  options.fit_board_warp = options.fit_board_relief = false;  // held at options.board_warp, the training fit's
  options.view_rms_ratio = HUGE_VAL;
  options.progress = nullptr;
  const FitResult fit = FitSensor(wide, target, posed, poses, options);
  if (!fit.sensor) {  // nothing fitted: no number, and why
    for (const ImageDetections& image : posed.images)
      held.not_evaluated[image.image] = "the poses could not be fitted: " + fit.solver_report;
    return held;
  }
  double square = 0.0;
  int count = 0;
  for (size_t v = 0; v < posed.images.size(); ++v) {
    double view_square = 0.0;
    int view_count = 0;
    if (v < fit.residuals_px.size()) AddView(fit.residuals_px[v], &view_square, &view_count);
    held.per_view_rms_px[posed.images[v].image] = view_count ? std::sqrt(view_square / view_count) : NAN;
    if (v < fit.view_left_out.size() && !fit.view_left_out[v].empty())
      held.not_evaluated[posed.images[v].image] = "its pose could not be fitted: " + fit.view_left_out[v];
    square += view_square, count += view_count;
  }
  held.corners = count;
  for (const ImageDetections& image : posed.images) held.unscored_corners += static_cast<int>(image.corners.size());
  held.unscored_corners -= count;
  held.rms_px = count ? std::sqrt(square / count) : NAN;
  held.inlier_rms_px = fit.rms_px;
  held.outliers = fit.outliers;
  return held;
}

TwoHalves CrossValidateHalves(const Sensor& start, const CalibrationTarget& target, const DetectionSet& views,
                              const std::vector<TargetPose>& initial_poses, FitOptions options,
                              const std::vector<Eigen::Vector2d>& field_pixels, double distance_mm,
                              double align_at_mm) {
  options.compute_covariance = false;
  options.progress = nullptr;
  TwoHalves halves;
  for (int half = 0; half < 2; ++half) {
    DetectionSet subset = views;
    subset.images.clear();
    std::vector<TargetPose> poses;
    for (size_t v = half; v < views.images.size(); v += 2) {
      subset.images.push_back(views.images[v]);
      poses.push_back(initial_poses[v]);
      halves.images[half].push_back(views.images[v].image);
    }
    if (subset.images.size() < 3)
      throw InputError("cross_validate: half " + std::to_string(half + 1) + " has " + std::to_string(subset.images.size()) +
                       " views (need >= 3 per half, >= 6 usable views in all)");
    const FitResult fit = FitSensor(start, target, subset, poses, options);
    if (!fit.sensor)
      throw InputError("cross_validate: the fit of half " + std::to_string(half + 1) + " failed: " + fit.solver_report);
    halves.rms_px[half] = fit.rms_px;
    halves.sensors.push_back(*fit.sensor);
  }
  halves.diff = CompareProjections(halves.sensors[0], halves.sensors[1], field_pixels, distance_mm);
  if (!std::isnan(align_at_mm)) {
    try {
      halves.diff_aligned_at_boards =
          CompareProjections(halves.sensors[0], halves.sensors[1], field_pixels, distance_mm, true, align_at_mm);
    } catch (const InputError&) {
      // Too few field pixels project at the boards' distance: the figure is left out, the
      // halves' comparison at distance_mm stands.
    }
  }
  return halves;
}

}  // namespace omnical

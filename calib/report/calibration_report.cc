#include "calib/report/calibration_report.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <utility>

#include "calib/cross_validation.h"
#include "calib/image_file.h"
#include "calib/report/plot.h"
#include "calib/report/projection_diff_figure.h"
#include "model/io/atomic_write.h"
#include "model/parallel_rows.h"

namespace omnical {
namespace {

// A map of the predicted projection error over the observed field, one cell per grid pixel.
void WritePredictedErrorMap(const std::string& path, const Sensor& sensor, const PredictedError& map, double step_px,
                            double threshold_px, const std::string& label) {
  cv::Mat picture(sensor.image_height_px(), sensor.image_width_px(), CV_8UC3, cv::Scalar(30, 30, 30));
  // Colour scale from 0 to the larger of the worst value and the warning threshold, so a
  // map under the threshold never looks alarming.
  const double top = std::max(threshold_px, map.max_px);
  for (size_t k = 0; k < map.pixels.size(); ++k) {
    if (!std::isfinite(map.std_px[k])) continue;
    const cv::Scalar colour = ColourMapColour(cv::COLORMAP_VIRIDIS, std::min(1.0, map.std_px[k] / top));
    const cv::Point2d corner(map.pixels[k].x() - 0.5 * step_px, map.pixels[k].y() - 0.5 * step_px);
    cv::rectangle(picture, cv::Rect2d(corner, cv::Size2d(step_px, step_px)), colour, cv::FILLED);
  }
  char text[200];
  std::snprintf(text, sizeof text, "predicted error at %s: median %.3f px, worst %.3f px", label.c_str(), map.median_px,
                map.max_px);
  cv::putText(picture, text, {10, 24}, cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  if (map.aligned_once) {
    std::snprintf(text, sizeof text, "after the rigid alignment fitted at %.0f mm, as omnical diff --align-at-mm",
                  map.aligned_at_mm);
  } else {
    std::snprintf(text, sizeof text, "after the best rigid alignment at this distance, as omnical diff");
  }
  cv::putText(picture, text, {10, 48}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  std::snprintf(text, sizeof text, "colour: 0 (purple) to %.3f px (yellow); warning above %.2f px", top, threshold_px);
  cv::putText(picture, text, {10, 70}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  WritePng(path, picture);
}

void WriteReport(const std::filesystem::path& dir, const DetectionSet& detections, const FitResult& fit,
                 const std::vector<NamedImage>& images, int threads) {
  CreateOutputDirectory(dir);
  double worst = 0.0;
  std::vector<double> magnitudes;
  for (const auto& view : fit.residuals_px)
    for (const Eigen::Vector2d& r : view)
      // Finite lengths only: a corner ~1e154 px off has an infinite norm, and a histogram
      // bin of infinite width indexed with NaN crashed the report.
      if (const double length = r.norm(); std::isfinite(length)) magnitudes.push_back(length), worst = std::max(worst, length);
  // Residual vectors on each image, scaled so the largest is ~40 px long.
  const double scale = worst > 0.0 ? std::pow(10.0, std::floor(std::log10(40.0 / worst))) : 1.0;
  cv::Mat coverage(detections.image_height_px, detections.image_width_px, CV_8UC3, cv::Scalar(30, 30, 30));
  for (size_t v = 0; v < detections.images.size(); ++v)
    for (const CornerObservation& corner : detections.images[v].corners)
      cv::circle(coverage, cv::Point2d(corner.pixel.x(), corner.pixel.y()), 2, SeriesColor(static_cast<int>(v)), cv::FILLED);
  // One whole camera frame per view: encoding them is most of the report's time, so the
  // views spread over threads.
  ParallelRows(static_cast<int>(detections.images.size()), threads, [&](int v) {
    const ImageDetections& image = detections.images[v];
    cv::Mat picture;
    if (images.empty()) {
      picture = ReadImageFile(image.image, cv::IMREAD_COLOR);
    } else {  // in memory: never a file that happens to have the view's name
      for (const NamedImage& named : images)
        if (named.name == image.image) cv::cvtColor(named.grey, picture, cv::COLOR_GRAY2BGR);
    }
    if (picture.empty()) picture = cv::Mat(detections.image_height_px, detections.image_width_px, CV_8UC3, cv::Scalar(40, 40, 40));
    for (size_t i = 0; i < image.corners.size(); ++i) {
      const cv::Point2d p(image.corners[i].pixel.x(), image.corners[i].pixel.y());
      const Eigen::Vector2d& r = fit.residuals_px[v][i];
      if (!std::isfinite(r.x())) {
        cv::drawMarker(picture, p, cv::Scalar(0, 0, 255), cv::MARKER_TILTED_CROSS, 8, 1);  // dropped
        continue;
      }
      cv::circle(picture, p, 2, cv::Scalar(0, 200, 0), cv::FILLED);
      cv::line(picture, p, p + cv::Point2d(r.x(), r.y()) * scale, cv::Scalar(0, 140, 255), 1, cv::LINE_AA);
    }
    char legend[160];
    std::snprintf(legend, sizeof legend, "residuals x%g (orange), RMS %.3f px; red crosses: dropped", scale,
                  fit.per_view_rms_px[v]);
    cv::putText(picture, legend, {10, 24}, cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
    WritePng((dir / ("residuals_view" + std::to_string(v) + ".png")).string(), picture);
  });
  cv::putText(coverage, "detected corners, one colour per view", {10, 24}, cv::FONT_HERSHEY_SIMPLEX, 0.6,
              cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  WritePng((dir / "coverage.png").string(), coverage);

  // Histogram of residual magnitudes and per-view RMS, drawn as steps.
  const int bins = 30;
  const double width = worst > 0.0 ? worst / bins : 1.0;
  std::vector<double> counts(bins, 0.0);
  for (double m : magnitudes) counts[std::min(bins - 1, static_cast<int>(m / width))] += 1.0;
  std::vector<double> x, y;
  for (int b = 0; b < bins; ++b) {
    x.insert(x.end(), {b * width, b * width, (b + 1) * width, (b + 1) * width});
    y.insert(y.end(), {0.0, counts[b], counts[b], 0.0});
  }
  PlotPanel histogram("Residual magnitudes", "|residual| (px)", "corners");
  histogram.series.push_back(PlotSeries("", x, y, SeriesColor(0)));
  WritePng((dir / "residual_histogram.png").string(), RenderPanel(histogram, 800, 500));
  x.clear(), y.clear();
  for (size_t v = 0; v < fit.per_view_rms_px.size(); ++v) {
    x.insert(x.end(), {v - 0.4, v - 0.4, v + 0.4, v + 0.4});
    y.insert(y.end(), {0.0, fit.per_view_rms_px[v], fit.per_view_rms_px[v], 0.0});
  }
  PlotPanel per_view("RMS reprojection error per view", "view", "RMS (px)");
  per_view.series.push_back(PlotSeries("", x, y, SeriesColor(1)));
  WritePng((dir / "per_view_rms.png").string(), RenderPanel(per_view, 800, 500));
}

// A bar from left to right at height `rms`, appended to a series' outline.
void AppendBar(double left, double right, double rms, std::vector<double>* x, std::vector<double>* y) {
  x->insert(x->end(), {left, left, right, right});
  y->insert(y->end(), {0.0, rms, rms, 0.0});
}

// Bars from 0 with a quarter of the height free above the tallest, where the legend goes
// (drawn over the bars it hid a view's top).
std::pair<double, double> BarsWithLegendRoom(const PlotPanel& panel) {
  double top = 0.0;
  for (const PlotSeries& s : panel.series)
    for (double y : s.y)
      if (std::isfinite(y)) top = std::max(top, y);
  return {0.0, top > 0.0 ? 1.3 * top : 1.0};
}

// Per-view RMS over all corners: the fitted views, then the held-out ones, with the
// training RMS as a line to compare with.
void WriteHoldoutFigure(const std::string& path, const CalibrationResult& result, const HeldOutViews& held) {
  const double training_rms_px = result.record.rms_all_px;
  char title[200];
  if (std::isfinite(held.rms_px))
    std::snprintf(title, sizeof title, "Per-view RMS, all corners: %zu held out at %.3f px, training %.3f px",
                  held.images.size(), held.rms_px, training_rms_px);
  else
    std::snprintf(title, sizeof title, "Per-view RMS, all corners: no held-out view evaluated, training %.3f px",
                  training_rms_px);
  PlotPanel panel(title, "view (fitted, then held out)", "RMS (px)");
  std::vector<double> x, y;
  double v = 0.0;
  for (const std::vector<Eigen::Vector2d>& residuals : result.fit.residuals_px) {
    const double rms = AllCornerViewRms(residuals);
    if (!std::isfinite(rms)) continue;
    AppendBar(v - 0.4, v + 0.4, rms, &x, &y);
    v += 1.0;
  }
  panel.series.push_back(PlotSeries("fitted", x, y, SeriesColor(0)));
  x.clear(), y.clear();
  for (const std::string& image : held.images) {
    const double rms = held.per_view_rms_px.count(image) ? held.per_view_rms_px.at(image) : NAN;
    if (std::isfinite(rms)) AppendBar(v - 0.4, v + 0.4, rms, &x, &y);
    v += 1.0;
  }
  panel.series.push_back(PlotSeries("held out", x, y, SeriesColor(1)));
  PlotSeries training("training RMS", {-0.5, v - 0.5}, {training_rms_px, training_rms_px}, SeriesColor(2));
  training.dashed = true;
  panel.series.push_back(training);
  panel.y_range = BarsWithLegendRoom(panel);
  WritePng(path, RenderPanel(panel, 800, 500));
}

// Each fitted view twice: its RMS in the full set's fit and when its fold held it out.
void WriteHoldoutFoldsFigure(const std::string& path, const CalibrationResult& result, const HeldOutFolds& folds) {
  char title[200];
  std::snprintf(title, sizeof title, "Every view held out once: %.3f px RMS, training %.3f px (all corners)",
                folds.rms_px, folds.training_rms_px);
  PlotPanel panel(title, "view", "RMS (px)");
  std::vector<double> fitted_x, fitted_y, held_x, held_y;
  double v = 0.0;
  for (size_t i = 0; i < result.fit.residuals_px.size() && i < result.views.images.size(); ++i) {
    const double rms = AllCornerViewRms(result.fit.residuals_px[i]);
    const auto held = folds.per_view_rms_px.find(result.views.images[i].image);
    if (!std::isfinite(rms) || held == folds.per_view_rms_px.end()) continue;
    AppendBar(v - 0.4, v - 0.02, rms, &fitted_x, &fitted_y);
    if (std::isfinite(held->second)) AppendBar(v + 0.02, v + 0.4, held->second, &held_x, &held_y);
    v += 1.0;
  }
  panel.series.push_back(PlotSeries("in the full fit", fitted_x, fitted_y, SeriesColor(0)));
  panel.series.push_back(PlotSeries("held out", held_x, held_y, SeriesColor(1)));
  panel.y_range = BarsWithLegendRoom(panel);
  WritePng(path, RenderPanel(panel, 800, 500));
}

}  // namespace

void WriteCalibrationReport(const std::string& dir, const CalibrationResult& result, const CalibrationOptions& options,
                            const std::vector<NamedImage>& images) {
  const std::filesystem::path path(dir);
  WriteReport(path, result.views, result.fit, images, options.threads);
  if (const auto& cross = result.record.cross_validation)
    WriteProjectionDiffFigure((path / "cross_validation.png").string(), cross->diff, result.sensor.image_width_px(),
                              result.sensor.image_height_px(), "two halves of the views, each calibrated: half 2 against half 1");
  if (const auto& held = result.record.holdout) WriteHoldoutFigure((path / "holdout.png").string(), result, *held);
  if (const auto& folds = result.record.holdout_folds)
    WriteHoldoutFoldsFigure((path / "holdout_folds.png").string(), result, *folds);
  for (size_t k = 0; k < result.predicted.size(); ++k)
    WritePredictedErrorMap((path / ("predicted_error_" + std::to_string(k) + ".png")).string(), result.sensor,
                           result.predicted[k], options.predicted_error_step_px, options.max_predicted_error_px,
                           result.distance_labels[k]);
}

}  // namespace omnical

#include "calib/report/projection_diff_figure.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "calib/predicted_error.h"
#include "calib/report/plot.h"

namespace omnical {

void WriteProjectionDiffFigure(const std::string& path, const ProjectionDiff& diff, int width_px, int height_px,
                               const std::string& title) {
  cv::Mat picture(height_px, width_px, CV_8UC3, cv::Scalar(30, 30, 30));
  // The grid's spacing, for the cells: the smallest distance between two field pixels.
  double step_px = HUGE_VAL;
  for (size_t k = 1; k < diff.pixels.size(); ++k) {
    const double d = (diff.pixels[k] - diff.pixels[k - 1]).norm();
    if (d > 0.0) step_px = std::min(step_px, d);
  }
  if (!std::isfinite(step_px)) step_px = 8.0;
  const double top = std::isfinite(diff.max_px) && diff.max_px > 0.0 ? diff.max_px : 1.0;
  const double scale = std::pow(10.0, std::floor(std::log10(std::max(1.0, 3.0 * step_px) / top)));
  for (size_t k = 0; k < diff.pixels.size(); ++k) {
    const Eigen::Vector2d& d = diff.difference_px[k];
    if (!d.allFinite()) continue;
    const cv::Scalar colour = ColourMapColour(cv::COLORMAP_VIRIDIS, std::min(1.0, d.norm() / top));
    const cv::Point2d centre(diff.pixels[k].x(), diff.pixels[k].y());
    cv::rectangle(picture, cv::Rect2d(centre - cv::Point2d(0.5 * step_px, 0.5 * step_px), cv::Size2d(step_px, step_px)),
                  colour, cv::FILLED);
  }
  // Arrows on a coarser grid (every third cell) so they stay readable.
  const double arrow_step = 3.0 * step_px;
  for (size_t k = 0; k < diff.pixels.size(); ++k) {
    const Eigen::Vector2d& d = diff.difference_px[k];
    const Eigen::Vector2d& p = diff.pixels[k];
    if (!d.allFinite() || std::fmod(std::abs(p.x()), arrow_step) >= step_px || std::fmod(std::abs(p.y()), arrow_step) >= step_px)
      continue;
    const cv::Point2d from(p.x(), p.y());
    cv::arrowedLine(picture, from, from + cv::Point2d(d.x(), d.y()) * scale, cv::Scalar(255, 255, 255), 1, cv::LINE_AA, 0, 0.3);
  }
  char text[300];
  cv::putText(picture, title, {10, 24}, cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  const std::string where = diff.distance_mm >= kInfinityMm ? std::string("infinity") : std::to_string(std::lround(diff.distance_mm)) + " mm";
  std::snprintf(text, sizeof text, "at %s, after the best rigid alignment (%.3f deg, %.2f mm): RMS %.3f px, max %.3f px, %d pixels",
                where.c_str(), diff.rotation_deg, diff.translation_mm.norm(), diff.rms_px, diff.max_px, diff.compared);
  cv::putText(picture, text, {10, 48}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  std::snprintf(text, sizeof text, "colour: |difference| 0 (purple) to %.3f px (yellow); arrows x%g", top, scale);
  cv::putText(picture, text, {10, 70}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  WritePng(path, picture);
}

}  // namespace omnical

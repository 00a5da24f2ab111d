#include "calib/report/plot.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <mutex>

#include "model/io/atomic_write.h"
#include "model/io/codecs/image_codecs.h"
#include "model/input_error.h"

namespace omnical {
namespace {

const cv::Scalar kBlack(0, 0, 0), kGrid(225, 225, 225), kWhite(255, 255, 255);
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;

std::string FormatTick(double value, double step) {
  char text[32];
  const int decimals = std::max(0, static_cast<int>(std::ceil(-std::log10(step) + 1e-9)));
  std::snprintf(text, sizeof text, "%.*f", std::min(decimals, 6), std::abs(value) < 1e-12 * step ? 0.0 : value);
  return text;
}

// 1, 2 or 5 times a power of ten, giving about `count` intervals over the range.
double NiceStep(double range, int count) {
  const double raw = range / count;
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (raw <= m * power) return m * power;
  return 10.0 * power;
}

void PutText(cv::Mat& image, const std::string& text, cv::Point origin, double scale, int anchor_x = 0,
             int anchor_y = 0) {
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, kFont, scale, 1, &baseline);
  origin.x -= anchor_x == 1 ? size.width / 2 : anchor_x == 2 ? size.width : 0;
  origin.y += anchor_y == 1 ? size.height / 2 : anchor_y == 2 ? size.height : 0;
  cv::putText(image, text, origin, kFont, scale, kBlack, 1, cv::LINE_AA);
}

void PutVerticalText(cv::Mat& image, const std::string& text, cv::Point centre, double scale) {
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, kFont, scale, 1, &baseline);
  cv::Mat label(size.height + baseline + 4, size.width + 4, image.type(), kWhite);
  cv::putText(label, text, cv::Point(2, size.height + 2), kFont, scale, kBlack, 1, cv::LINE_AA);
  cv::rotate(label, label, cv::ROTATE_90_COUNTERCLOCKWISE);
  const cv::Rect where(centre.x - label.cols / 2, centre.y - label.rows / 2, label.cols, label.rows);
  if ((where & cv::Rect(0, 0, image.cols, image.rows)) == where) label.copyTo(image(where));
}

// The legend's entries: the labelled series', then the labelled bands'.
std::vector<std::string> LegendLabels(const PlotPanel& panel) {
  std::vector<std::string> labels;
  for (const PlotSeries& s : panel.series)
    if (!s.label.empty()) labels.push_back(s.label);
  for (const PlotBand& b : panel.bands)
    if (!b.label.empty()) labels.push_back(b.label);
  return labels;
}

}  // namespace

cv::Scalar SeriesColor(int index) {
  // Okabe-Ito palette, BGR.
  static const cv::Scalar kColors[] = {{178, 114, 0}, {0, 94, 213}, {115, 158, 0}, {167, 121, 204},
                                       {233, 180, 86}, {66, 228, 240}, {0, 159, 230}, {60, 60, 60}};
  return kColors[index % 8];
}

cv::Mat RenderPanel(const PlotPanel& panel, int width_px, int height_px) {
  cv::Mat image(height_px, width_px, CV_8UC3, kWhite);
  const int left = 78, right = 18, top = 34, bottom = 52;
  const cv::Rect plot(left, top, width_px - left - right, height_px - top - bottom);

  double x0 = HUGE_VAL, x1 = -HUGE_VAL, y0 = HUGE_VAL, y1 = -HUGE_VAL;
  for (const PlotSeries& s : panel.series) {
    for (size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      x0 = std::min(x0, s.x[i]), x1 = std::max(x1, s.x[i]);
      y0 = std::min(y0, s.y[i]), y1 = std::max(y1, s.y[i]);
    }
  }
  for (const PlotBand& b : panel.bands) y0 = std::min({y0, b.y0, b.y1}), y1 = std::max({y1, b.y0, b.y1});
  if (!(x1 >= x0)) x0 = 0.0, x1 = 1.0;
  if (!(y1 >= y0)) y0 = 0.0, y1 = 1.0;
  if (x1 - x0 < 1e-12) x0 -= 0.5, x1 += 0.5;
  if (y1 - y0 < 1e-12 * std::max(1.0, std::abs(y0))) y0 -= 0.5, y1 += 0.5;
  const double pad_y = 0.05 * (y1 - y0);
  y0 -= pad_y, y1 += pad_y;
  if (panel.x_range) x0 = panel.x_range->first, x1 = panel.x_range->second;
  if (panel.y_range) y0 = panel.y_range->first, y1 = panel.y_range->second;
  if (panel.equal_aspect) {
    const double scale = std::max((x1 - x0) / plot.width, (y1 - y0) / plot.height);
    const double cx = 0.5 * (x0 + x1), cy = 0.5 * (y0 + y1);
    x0 = cx - 0.5 * scale * plot.width, x1 = cx + 0.5 * scale * plot.width;
    y0 = cy - 0.5 * scale * plot.height, y1 = cy + 0.5 * scale * plot.height;
  }
  auto to_px = [&](double x, double y) {
    return cv::Point2d(plot.x + (x - x0) / (x1 - x0) * plot.width, plot.y + plot.height - (y - y0) / (y1 - y0) * plot.height);
  };

  for (const PlotBand& b : panel.bands) {
    const cv::Point2d p0 = to_px(x0, b.y0), p1 = to_px(x1, b.y1);
    cv::rectangle(image, cv::Rect(cv::Point(p0), cv::Point(p1)) & plot, cv::Scalar(215, 240, 215), cv::FILLED);
  }
  // Grid, ticks and tick labels.
  const double step_x = NiceStep(x1 - x0, 6), step_y = NiceStep(y1 - y0, 5);
  for (double t = std::ceil(x0 / step_x) * step_x; t <= x1 + 1e-9 * step_x; t += step_x) {
    const int px = static_cast<int>(std::lround(to_px(t, y0).x));
    cv::line(image, {px, plot.y}, {px, plot.y + plot.height}, kGrid, 1);
    PutText(image, FormatTick(t, step_x), {px, plot.y + plot.height + 6}, 0.42, 1, 2);
  }
  for (double t = std::ceil(y0 / step_y) * step_y; t <= y1 + 1e-9 * step_y; t += step_y) {
    const int py = static_cast<int>(std::lround(to_px(x0, t).y));
    cv::line(image, {plot.x, py}, {plot.x + plot.width, py}, kGrid, 1);
    PutText(image, FormatTick(t, step_y), {plot.x - 6, py}, 0.42, 2, 1);
  }
  cv::rectangle(image, plot, kBlack, 1);

  cv::Mat canvas = image(plot);
  const cv::Point offset(plot.x, plot.y);
  for (const PlotSeries& s : panel.series) {
    for (size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      const cv::Point p = cv::Point(to_px(s.x[i], s.y[i])) - offset;
      if (s.markers_only) {
        cv::circle(canvas, p, s.thickness + 1, s.color, cv::FILLED, cv::LINE_AA);
        continue;
      }
      if (i == 0 || !std::isfinite(s.x[i - 1]) || !std::isfinite(s.y[i - 1])) continue;
      if (s.dashed && (i / 4) % 2 == 1) continue;
      cv::line(canvas, cv::Point(to_px(s.x[i - 1], s.y[i - 1])) - offset, p, s.color, s.thickness, cv::LINE_AA);
    }
  }
  // Legend, top right: as wide as its longest label (a fixed width cut long ones at the
  // panel's edge). Drawn over the data, not on a box that would hide where curves end.
  int label_width_px = 0;
  for (const std::string& label : LegendLabels(panel)) {
    int baseline = 0;
    label_width_px = std::max(label_width_px, cv::getTextSize(label, kFont, 0.42, 1, &baseline).width);
  }
  const int legend_x = plot.x + plot.width - std::min(plot.width - 8, 30 + label_width_px + 8) - 4;
  int row = 0;
  for (const PlotSeries& s : panel.series) {
    if (s.label.empty()) continue;
    const cv::Point at(legend_x, plot.y + 14 + 18 * row++);
    if (s.markers_only) {
      cv::circle(image, at + cv::Point(12, -4), s.thickness + 1, s.color, cv::FILLED, cv::LINE_AA);
    } else {
      cv::line(image, at + cv::Point(0, -4), at + cv::Point(24, -4), s.color, s.thickness, cv::LINE_AA);
    }
    PutText(image, s.label, at + cv::Point(30, 0), 0.42);
  }
  for (const PlotBand& b : panel.bands) {
    if (b.label.empty()) continue;
    const cv::Point at(legend_x, plot.y + 14 + 18 * row++);
    cv::rectangle(image, cv::Rect(at + cv::Point(0, -9), cv::Size(24, 10)), cv::Scalar(215, 240, 215), cv::FILLED);
    PutText(image, b.label, at + cv::Point(30, 0), 0.42);
  }
  PutText(image, panel.title, {width_px / 2, 10}, 0.55, 1, 2);
  PutText(image, panel.x_label, {plot.x + plot.width / 2, height_px - 8}, 0.5, 1, 0);
  PutVerticalText(image, panel.y_label, {16, plot.y + plot.height / 2}, 0.5);
  return image;
}

cv::Mat TilePanels(const std::vector<cv::Mat>& panels, int columns) {
  std::vector<cv::Mat> rows;
  for (size_t start = 0; start < panels.size(); start += columns) {
    std::vector<cv::Mat> row(panels.begin() + start, panels.begin() + std::min(panels.size(), start + columns));
    while (static_cast<int>(row.size()) < columns && panels.size() > static_cast<size_t>(columns))
      row.push_back(cv::Mat(panels[0].size(), panels[0].type(), kWhite));
    cv::Mat joined;
    cv::hconcat(row, joined);
    rows.push_back(joined);
  }
  cv::Mat out;
  cv::vconcat(rows, out);
  return out;
}

cv::Scalar ColourMapColour(int colormap, double fraction) {
  // One 256-entry table per colour map, made by OpenCV itself so colours match
  // cv::applyColorMap exactly; figures may be drawn from several threads.
  static std::mutex tables_mutex;
  static std::map<int, cv::Mat> tables;
  cv::Mat table;
  {
    std::lock_guard<std::mutex> lock(tables_mutex);
    cv::Mat& entry = tables[colormap];
    if (entry.empty()) {
      cv::Mat ramp(256, 1, CV_8UC1);
      for (int level = 0; level < 256; ++level) ramp.at<uchar>(level) = static_cast<uchar>(level);
      cv::applyColorMap(ramp, entry, colormap);
    }
    table = entry;
  }
  const double clamped = std::isfinite(fraction) ? std::clamp(fraction, 0.0, 1.0) : 0.0;
  const cv::Vec3b colour = table.at<cv::Vec3b>(static_cast<int>(std::lround(255.0 * clamped)));
  return cv::Scalar(colour[0], colour[1], colour[2]);
}

cv::Mat RenderFalseColourMap(const cv::Mat& values, const std::string& title, const std::string& unit) {
  double lo = HUGE_VAL, hi = -HUGE_VAL;
  for (int r = 0; r < values.rows; ++r)
    for (int c = 0; c < values.cols; ++c) {
      const float v = values.at<float>(r, c);
      if (std::isfinite(v)) lo = std::min(lo, double(v)), hi = std::max(hi, double(v));
    }
  if (!(hi >= lo)) lo = 0.0, hi = 1.0;
  if (hi - lo < 1e-12) hi = lo + 1.0;
  cv::Mat scaled(values.size(), CV_8UC1);
  cv::Mat valid(values.size(), CV_8UC1);
  for (int r = 0; r < values.rows; ++r)
    for (int c = 0; c < values.cols; ++c) {
      const float v = values.at<float>(r, c);
      valid.at<uchar>(r, c) = std::isfinite(v) ? 255 : 0;
      scaled.at<uchar>(r, c) = std::isfinite(v) ? cv::saturate_cast<uchar>(255.0 * (v - lo) / (hi - lo)) : 0;
    }
  cv::Mat colour;
  cv::applyColorMap(scaled, colour, cv::COLORMAP_TURBO);
  colour.setTo(cv::Scalar(0, 0, 0), valid == 0);
  // Title above, scale bar to the right.
  const int bar_width = 130, title_height = 36;
  cv::Mat out(colour.rows + title_height, colour.cols + bar_width, CV_8UC3, kWhite);
  colour.copyTo(out(cv::Rect(0, title_height, colour.cols, colour.rows)));
  PutText(out, title, {colour.cols / 2, 8}, 0.6, 1, 2);
  const int bar_top = title_height + 20, bar_height = colour.rows - 40, bar_x = colour.cols + 16;
  for (int i = 0; i < bar_height; ++i)
    cv::line(out, {bar_x, bar_top + i}, {bar_x + 24, bar_top + i},
             ColourMapColour(cv::COLORMAP_TURBO, 1.0 - double(i) / std::max(1, bar_height - 1)), 1);
  cv::rectangle(out, cv::Rect(bar_x, bar_top, 25, bar_height), kBlack, 1);
  const double step = NiceStep(hi - lo, 6);
  for (double t = std::ceil(lo / step) * step; t <= hi + 1e-9 * step; t += step) {
    const int y = bar_top + static_cast<int>(std::lround((hi - t) / (hi - lo) * (bar_height - 1)));
    cv::line(out, {bar_x + 25, y}, {bar_x + 30, y}, kBlack, 1);
    PutText(out, FormatTick(t, step), {bar_x + 34, y}, 0.42, 0, 1);
  }
  PutText(out, unit, {bar_x + 12, bar_top + bar_height + 8}, 0.45, 1, 2);
  return out;
}

void WritePng(const std::string& path, const cv::Mat& image) {
  std::vector<uchar> bytes;
  // Small figures compress hard (they are committed under docs/). Large images (report
  // overlays of whole camera frames) take OpenCV's speed settings, which it applies only
  // when no level is given: one row filter (SUB) and zlib level 1. Any explicit level
  // also makes libpng try every filter on every row, which was most of `calibrate
  // --detections` on the real dev set.
  const bool large = image.total() > 500000;
  const bool encoded = large ? EncodeImage(".png", image, &bytes)
                             : EncodeImage(".png", image, &bytes, {cv::IMWRITE_PNG_COMPRESSION, 9});
  if (!encoded) throw InputError(InputMessage(path, "", "cannot encode PNG"));
  WriteFileAtomically(path, [&](std::ostream& out) { out.write(reinterpret_cast<const char*>(bytes.data()), bytes.size()); });
}

}  // namespace omnical

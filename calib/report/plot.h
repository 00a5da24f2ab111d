// Line plots and false-colour maps drawn with OpenCV, for the figures the subcommands
// write (PNG). Deliberately small: axes with ticks and units, several series, a legend,
// shaded bands, optional equal aspect.
#pragma once

#include <opencv2/core.hpp>

#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace omnical {

struct PlotSeries {
  PlotSeries(std::string label_, std::vector<double> x_, std::vector<double> y_, cv::Scalar color_)
      : label(std::move(label_)), x(std::move(x_)), y(std::move(y_)), color(color_) {}
  std::string label;  // empty: not in the legend
  std::vector<double> x, y;
  cv::Scalar color;
  int thickness = 2;
  bool dashed = false;
  bool markers_only = false;  // draw points, not a line
};

struct PlotBand {  // a shaded horizontal band y0..y1
  double y0, y1;
  std::string label;
};

struct PlotPanel {
  PlotPanel(std::string title_, std::string x_label_, std::string y_label_)
      : title(std::move(title_)), x_label(std::move(x_label_)), y_label(std::move(y_label_)) {}
  std::string title, x_label, y_label;  // labels carry their units, e.g. "Omega (deg)"
  std::vector<PlotSeries> series;
  std::vector<PlotBand> bands;
  std::optional<std::pair<double, double>> x_range, y_range;
  bool equal_aspect = false;
};

// A distinct colour per series index (colour-blind friendly order).
cv::Scalar SeriesColor(int index);

cv::Mat RenderPanel(const PlotPanel& panel, int width_px, int height_px);

// Panels side by side in rows of `columns`.
cv::Mat TilePanels(const std::vector<cv::Mat>& panels, int columns);

// The colour an OpenCV colour map (cv::COLORMAP_*) gives a fraction in [0, 1] (clamped).
// Figures colour thousands of cells one at a time; cv::applyColorMap on a 1 x 1 image per
// cell rebuilt its table each call and was a third of `calibrate`'s time.
cv::Scalar ColourMapColour(int colormap, double fraction);

// A false-colour map of `values` (NaN = no data, drawn black) with a labelled scale bar.
cv::Mat RenderFalseColourMap(const cv::Mat& values, const std::string& title, const std::string& unit);

// PNG written atomically; throws InputError naming the path on failure.
void WritePng(const std::string& path, const cv::Mat& image);

}  // namespace omnical

#include "calib/report/profile_drawing.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "model/io/atomic_write.h"
#include "model/input_error.h"
#include "calib/report/plot.h"

namespace omnical {
namespace {

constexpr int kWidthPx = 1600, kHeightPx = 1000;

// The layout as primitives in canvas pixels (y down), emitted to SVG and to PNG.
struct Stroke {
  std::vector<cv::Point2d> points;
  double width = 2.0;
  bool dashed = false;
};
struct Label {
  cv::Point2d at;  // baseline: left end, or centre when centred
  std::string text;
  double size_px = 18.0;
  bool centred = false;
};
struct Layout {
  std::vector<Stroke> strokes;
  std::vector<Label> labels;

  void Line(cv::Point2d a, cv::Point2d b, double width = 1.0, bool dashed = false) { strokes.push_back({{a, b}, width, dashed}); }
  void Text(cv::Point2d at, std::string text, double size_px = 18.0, bool centred = false) {
    labels.push_back({at, std::move(text), size_px, centred});
  }
  // A dimension line a-b with arrowheads at both ends.
  void Dimension(cv::Point2d a, cv::Point2d b) {
    Line(a, b);
    const cv::Point2d along = (b - a) / cv::norm(b - a), across(-along.y, along.x);
    for (const auto& [tip, dir] : {std::pair{a, along}, std::pair{b, -along}}) {
      Line(tip, tip + 14.0 * dir + 5.0 * across);
      Line(tip, tip + 14.0 * dir - 5.0 * across);
    }
  }
};

// The sample interval [i, i + 1] holding radius r.
size_t IntervalOf(const ProfileTable& p, double r) {
  const auto upper = std::upper_bound(p.radius_mm.begin(), p.radius_mm.end(), r);
  return std::clamp<size_t>(upper - p.radius_mm.begin(), 1, p.radius_mm.size() - 1) - 1;
}

// Cubic Hermite through the samples (value and slope), so stations between samples keep
// the design's accuracy.
double SagAt(const ProfileDrawing& d, double r) {
  const ProfileTable& p = d.profile;
  const size_t i = IntervalOf(p, r);
  const double h = p.radius_mm[i + 1] - p.radius_mm[i], t = (r - p.radius_mm[i]) / h;
  const double h00 = (1 + 2 * t) * (1 - t) * (1 - t), h10 = t * (1 - t) * (1 - t), h01 = t * t * (3 - 2 * t), h11 = t * t * (t - 1);
  return h00 * p.sag_mm[i] + h10 * h * p.slope[i] + h01 * p.sag_mm[i + 1] + h11 * h * p.slope[i + 1];
}
double SlopeAt(const ProfileDrawing& d, double r) {
  const ProfileTable& p = d.profile;
  const size_t i = IntervalOf(p, r);
  const double t = (r - p.radius_mm[i]) / (p.radius_mm[i + 1] - p.radius_mm[i]);
  return (1 - t) * p.slope[i] + t * p.slope[i + 1];
}

std::string Fixed(double value, int digits) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", digits, value);
  return text;
}

Layout MakeLayout(const ProfileDrawing& d) {
  Layout layout;
  const double rim = d.profile.radius_mm.back(), rim_sag = d.profile.sag_mm.back();
  // The section to scale in the left 1000 x 1000 px, vertex low, the lens side below.
  const double scale = std::min(600.0 / (2.0 * rim), 540.0 / std::max(rim_sag, 1e-9));
  const cv::Point2d vertex(430.0, 740.0);
  auto at = [&](double r, double z) { return cv::Point2d(vertex.x + scale * r, vertex.y - scale * z); };

  layout.Text({800.0, 40.0}, d.title, 26.0, true);
  Stroke surface;
  surface.width = 3.0;
  for (size_t i = d.profile.radius_mm.size(); i-- > 0;) surface.points.push_back(at(-d.profile.radius_mm[i], d.profile.sag_mm[i]));
  for (size_t i = 1; i < d.profile.radius_mm.size(); ++i) surface.points.push_back(at(d.profile.radius_mm[i], d.profile.sag_mm[i]));
  layout.strokes.push_back(surface);
  layout.Line(at(-rim, rim_sag), at(rim, rim_sag), 1.0, true);  // the rim plane
  // The axis between the vertex note and the diameter's dimension line.
  layout.Line(at(0, 0) + cv::Point2d(0, 40), at(0, rim_sag) - cv::Point2d(0, 25), 1.0, true);
  layout.Text(at(0, rim_sag) + cv::Point2d(8, -12), "axis", 16.0);

  // Diameter above the rim plane.
  const double dim_y = at(0, rim_sag).y - 50.0;
  layout.Line(at(-rim, rim_sag), {at(-rim, 0).x, dim_y - 8.0});
  layout.Line(at(rim, rim_sag), {at(rim, 0).x, dim_y - 8.0});
  layout.Dimension({at(-rim, 0).x, dim_y}, {at(rim, 0).x, dim_y});
  layout.Text({vertex.x, dim_y - 10.0}, "DIA " + Fixed(2.0 * rim, 3), 20.0, true);
  // Sag at the rim, to the right of the section.
  const double dim_x = at(rim, 0).x + 50.0;
  layout.Line(at(0, 0), {dim_x + 8.0, vertex.y});
  layout.Line(at(rim, rim_sag), {dim_x + 8.0, at(rim, rim_sag).y});
  layout.Dimension({dim_x, vertex.y}, {dim_x, at(rim, rim_sag).y});
  layout.Text({dim_x + 12.0, 0.5 * (vertex.y + at(rim, rim_sag).y)}, "sag " + Fixed(rim_sag, 3), 20.0);
  layout.Text({vertex.x, vertex.y + 70.0}, "vertex (x = 0, z = 0); lens side below", 16.0, true);
  // A scale bar, so a print can be checked.
  const double bar_mm = std::pow(10.0, std::floor(std::log10(rim)));
  layout.Dimension({60.0, 930.0}, {60.0 + scale * bar_mm, 930.0});
  layout.Text({60.0, 915.0}, "scale: " + Fixed(bar_mm, bar_mm < 1.0 ? 2 : 0) + " mm", 16.0);

  // The table of ordinates at the right.
  const double left = 1040.0, columns[] = {0.0, 120.0, 250.0, 380.0};
  double y = 110.0;
  const char* headers[] = {"x (mm)", "z (mm)", "dz/dx", "slope (deg)"};
  for (int c = 0; c < 4; ++c) layout.Text({left + columns[c], y}, headers[c], 18.0);
  layout.Line({left - 10.0, y + 8.0}, {left + 500.0, y + 8.0});
  const int stations = std::max(2, d.stations);
  const double row = std::min(34.0, 600.0 / stations);
  for (int i = 0; i <= stations; ++i) {
    const double r = rim * i / stations;
    const double z = i == 0 ? d.profile.sag_mm.front() : i == stations ? rim_sag : SagAt(d, r);
    const double slope = i == 0 ? d.profile.slope.front() : i == stations ? d.profile.slope.back() : SlopeAt(d, r);
    y += row;
    const std::string cells[] = {Fixed(r, 3), Fixed(z, 3), Fixed(slope, 5), Fixed(std::atan(slope) * 180.0 / M_PI, 3)};
    for (int c = 0; c < 4; ++c) layout.Text({left + columns[c], y}, cells[c], 17.0);
  }
  y += 40.0;
  std::vector<std::string> notes = {"All dimensions in mm. Surface of revolution about the axis;",
                                    "z measured from the vertex, away from the lens."};
  // The reflection ODE can give the axis a cone point; a workshop must know.
  if (std::abs(d.profile.slope.front()) > 1e-6)
    notes.push_back("The vertex is a cone point: slope " + Fixed(std::atan(d.profile.slope.front()) * 180.0 / M_PI, 3) + " deg at x = 0.");
  notes.insert(notes.end(), d.notes.begin(), d.notes.end());
  for (const std::string& note : notes) {
    layout.Text({left - 10.0, y}, note, 15.0);
    y += 24.0;
  }
  return layout;
}

std::string EscapeXml(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '&') out += "&amp;";
    else out += c;
  }
  return out;
}

void WriteSvg(const Layout& layout, const std::string& path) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << kWidthPx << "\" height=\"" << kHeightPx << "\" viewBox=\"0 0 "
        << kWidthPx << ' ' << kHeightPx << "\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
    out.precision(6);
    for (const Stroke& s : layout.strokes) {
      out << "<polyline fill=\"none\" stroke=\"black\" stroke-width=\"" << s.width << '"'
          << (s.dashed ? " stroke-dasharray=\"12 4 2 4\"" : "") << " points=\"";
      for (const cv::Point2d& p : s.points) out << p.x << ',' << p.y << ' ';
      out << "\"/>\n";
    }
    for (const Label& l : layout.labels)
      out << "<text x=\"" << l.at.x << "\" y=\"" << l.at.y << "\" font-family=\"sans-serif\" font-size=\"" << l.size_px << '"'
          << (l.centred ? " text-anchor=\"middle\"" : "") << '>' << EscapeXml(l.text) << "</text>\n";
    out << "</svg>\n";
  });
}

cv::Mat RenderPng(const Layout& layout) {
  cv::Mat image(kHeightPx, kWidthPx, CV_8UC3, cv::Scalar(255, 255, 255));
  const cv::Scalar black(0, 0, 0);
  for (const Stroke& s : layout.strokes) {
    const int width = std::max(1, static_cast<int>(std::lround(s.width)));
    for (size_t i = 1; i < s.points.size(); ++i) {
      const cv::Point2d a = s.points[i - 1], b = s.points[i];
      if (!s.dashed) {
        cv::line(image, a, b, black, width, cv::LINE_AA);
        continue;
      }
      const double length = cv::norm(b - a);
      for (double t = 0.0; t < length; t += 22.0)
        cv::line(image, a + (b - a) * (t / length), a + (b - a) * (std::min(t + 12.0, length) / length), black, width, cv::LINE_AA);
    }
  }
  for (const Label& l : layout.labels) {
    const double font_scale = l.size_px / 30.0;
    int baseline = 0;
    const cv::Size size = cv::getTextSize(l.text, cv::FONT_HERSHEY_SIMPLEX, font_scale, 1, &baseline);
    const cv::Point origin(static_cast<int>(l.at.x - (l.centred ? 0.5 * size.width : 0.0)), static_cast<int>(l.at.y));
    cv::putText(image, l.text, origin, cv::FONT_HERSHEY_SIMPLEX, font_scale, black, 1, cv::LINE_AA);
  }
  return image;
}

}  // namespace

void WriteProfileDrawing(const ProfileDrawing& drawing, const std::string& svg_path, const std::string& png_path) {
  const Layout layout = MakeLayout(drawing);
  WriteSvg(layout, svg_path);
  WritePng(png_path, RenderPng(layout));
}

}  // namespace omnical

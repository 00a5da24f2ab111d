#include "calib/report/correction_figures.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "calib/report/plot.h"

namespace omnical {
namespace {

std::string In(const std::string& dir, const char* name) { return (std::filesystem::path(dir) / name).string(); }

// log10 n, max and rms of the finite distances of a sweep.
struct SweepCurve {
  std::vector<double> log_n, max_px, rms_px;
};
SweepCurve CurveOf(const std::vector<RemapErrorAtDistance>& errors) {
  SweepCurve curve;
  for (const RemapErrorAtDistance& e : errors) {
    if (!std::isfinite(e.n)) continue;
    curve.log_n.push_back(std::log10(e.n));
    curve.max_px.push_back(e.stats.max_px);
    curve.rms_px.push_back(e.stats.rms_px);
  }
  return curve;
}

}  // namespace

void WriteRemapFigures(const std::string& dir, const RemapResult& result) {
  const SweepCurve curve = CurveOf(result.error_at_other_distances);
  PlotPanel panel{"Error of this table for objects at other distances (n rim radii from V0)",
                  "log10 n (object distance in mirror rim radii)", "error (output px)"};
  panel.series.push_back({"max", curve.log_n, curve.max_px, SeriesColor(0)});
  panel.series.push_back({"rms", curve.log_n, curve.rms_px, SeriesColor(1)});
  WritePng(In(dir, "remap_error.png"), RenderPanel(panel, 900, 520));
}

void WriteParallaxFigures(const std::string& dir, const ParallaxResult& result) {
  char title[160];
  std::snprintf(title, sizeof title, "Viewpoint error, object at n = %.3g mirror radii (%.0f mm), V0 = %.3f mm", result.n,
                result.distance_mm, result.v0_mm);
  PlotPanel panel{title, "Omega (deg)", "error (px in the omni image)"};
  panel.series.push_back({"epsilon x dh/dOmega", result.curve.omega_deg, result.curve.error_px, SeriesColor(0)});
  WritePng(In(dir, "parallax.png"), RenderPanel(panel, 900, 560));

  const ParallaxMap& map = result.map;
  const cv::Mat values(map.height, map.width, CV_32F, const_cast<float*>(map.error_px.data()));
  std::snprintf(title, sizeof title, "|error| of a central projector at V0, object at n = %.3g", result.n);
  WritePng(In(dir, "error_map.png"), RenderFalseColourMap(values, title, "px"));
}

void WriteMapsErrorFigures(const std::string& dir, const MapsErrorResult& result) {
  const SweepCurve curve = CurveOf(result.errors);
  const RemapSettings& settings = result.maps.settings;
  const double at_infinity = result.errors.back().stats.max_px;
  char title[200];
  std::snprintf(title, sizeof title, "%s %dx%d made for objects %s%s: error elsewhere", ScreenTypeName(settings.screen.type),
                settings.screen.width_px, settings.screen.height_px,
                settings.surface.kind == ObjectSurface::Kind::kInfinity ? "at " : "on ", result.made_for.c_str());
  PlotPanel panel{title, "log10 n (object distance from V0 in mirror rim radii)", "error (output px)"};
  panel.series.push_back({"max", curve.log_n, curve.max_px, SeriesColor(0)});
  panel.series.push_back({"rms", curve.log_n, curve.rms_px, SeriesColor(1)});
  panel.series.push_back({"at infinity (max)", {curve.log_n.front(), curve.log_n.back()}, {at_infinity, at_infinity}, SeriesColor(2)});
  panel.series.back().dashed = true;
  WritePng(In(dir, "maps-error.png"), RenderPanel(panel, 900, 560));
}

void WriteCentralExportFigures(const std::string& dir, const CentralExportResult& result) {
  char title[200];
  std::snprintf(title, sizeof title, "%s central model fitted for %s: error of each field sample",
                result.model == CentralModelKind::kMei ? "Mei (cv::omnidir)" : "OCamCalib", result.FittedForText().c_str());
  PlotPanel panel{title, "Omega (deg)", "error (px in the omni image)"};
  panel.series.push_back({"samples", result.error.omega_deg, result.error.error_px, SeriesColor(0)});
  panel.series.back().markers_only = true;
  WritePng(In(dir, "central_error.png"), RenderPanel(panel, 900, 560));
}

}  // namespace omnical

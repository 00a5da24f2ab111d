#include "calib/report/design_figures.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "calib/report/plot.h"
#include "calib/report/profile_drawing.h"

namespace omnical {
namespace {

std::string InDir(const std::string& dir, const char* name) { return (std::filesystem::path(dir) / name).string(); }

const char* LawName(ImagingLaw::Kind kind) {
  return kind == ImagingLaw::Kind::kLinear ? "linear" : kind == ImagingLaw::Kind::kLogPolar ? "log-polar" : "tabulated";
}

// h vs Omega of one sensor, or its departure from the law.
PlotSeries Curve(const std::string& label, const CharacteristicReport& r, int color, bool deviation,
                 ImageCharacteristic law) {
  std::vector<double> omega, value;
  for (const CharacteristicSample& s : r.samples) {
    omega.push_back(s.omega_deg);
    const double h_law = r.rim_h_px * LawHeightRatio(law, s.omega_deg * M_PI / 180.0, r.rim_omega_deg * M_PI / 180.0);
    value.push_back(deviation ? s.h_px - h_law : s.h_px);
  }
  return PlotSeries(label, omega, value, SeriesColor(color));
}

}  // namespace

void WriteOdeDesignFigures(const DesignOdeResult& r, const std::string& dir) {
  const OdeDesignSpec& spec = r.spec;
  const OdeDesign& design = r.design;
  PlotPanel ratio("Imaging law through the designed mirror (1 = the law, scaled by distance / d)", "rho (mm)",
                  "traced dh / law dh, / (d_i / d)");
  for (size_t k = 0; k < r.law_ratio.size(); ++k) {
    char label[64];
    std::snprintf(label, sizeof label, "cylinder at %.0f mm%s", r.law_ratio[k].distance_mm,
                  static_cast<int>(k) == DesignOdeResult::kReferenceCurve ? " (design)" : "");
    ratio.series.emplace_back(label, r.law_ratio[k].rho_mm, r.law_ratio[k].ratio, SeriesColor(static_cast<int>(k)));
  }
  PlotPanel profile("Mirror profile", "x (mm)", "sag z (mm)");
  profile.equal_aspect = true;
  profile.series.emplace_back("profile", r.profile.radius_mm, r.profile.sag_mm, SeriesColor(0));
  PlotPanel rays("Rays: image -> pinhole -> mirror -> reference cylinder", "radius (mm)",
                 "height above the image plane (mm)");
  for (int i = 0; i <= 12; ++i) {
    const double rho = spec.rho0_mm + (design.rho_end_mm - spec.rho0_mm) * i / 12.0;
    // The mirror point of rho: on the profile where f t / (F - f) = rho.
    const auto it =
        std::lower_bound(design.profile.begin(), design.profile.end(), rho, [&](const ProfileSample& s, double v) {
          return spec.focal_length_mm * s.radius_mm / (s.height_mm - spec.focal_length_mm) < v;
        });
    if (it == design.profile.end()) continue;
    const double h = TracedHeightMm(r.sensor, spec, r.pixel_pitch_mm, rho, spec.distance_mm);
    rays.series.emplace_back("", std::vector<double>{-rho, 0.0, it->radius_mm, spec.distance_mm},
                             std::vector<double>{0.0, spec.focal_length_mm, it->height_mm, h},
                             cv::Scalar(160, 160, 160));
    rays.series.back().thickness = 1;
  }
  rays.series.emplace_back("mirror", r.profile.radius_mm, std::vector<double>(), SeriesColor(1));
  for (const ProfileSample& s : design.profile) rays.series.back().y.push_back(s.height_mm);
  WritePng(InDir(dir, "law_ratio.png"), RenderPanel(ratio, 900, 500));
  WritePng(InDir(dir, "profile.png"), TilePanels({RenderPanel(profile, 700, 450), RenderPanel(rays, 700, 450)}, 2));

  ProfileDrawing drawing;
  drawing.profile = r.profile;
  char title[160], lens_note[200], plane_note[120];
  std::snprintf(title, sizeof title, "omnical design ode: %s law on a cylinder at d = %.0f mm", LawName(spec.law.kind),
                spec.distance_mm);
  std::snprintf(lens_note, sizeof lens_note, "Pinhole (f = %.3f mm) %.3f mm below the vertex (m),",
                spec.focal_length_mm, r.m_mm);
  std::snprintf(plane_note, sizeof plane_note, "image plane %.3f mm below the vertex (F0).", r.vertex_height_mm);
  drawing.title = title;
  drawing.notes = {lens_note, plane_note, "Full table: profile.csv; the model: sensor.yaml."};
  WriteProfileDrawing(drawing, InDir(dir, "profile_drawing.svg"), InDir(dir, "profile_drawing.png"));
}

void WriteFitDesignFigures(const DesignFitResult& r, const std::string& dir) {
  const FitDesignSpec& spec = r.spec;
  ProfileDrawing drawing;
  drawing.profile = r.profile;
  char lens_note[160];
  std::snprintf(lens_note, sizeof lens_note, "Lens principal point on the axis %.3f mm below the vertex (m).",
                r.design.m * r.rim_radius_mm);
  drawing.title = std::string("omnical design fit: ") + spec.profile +
                  (spec.characteristic == ImageCharacteristic::kNone
                       ? std::string()
                       : std::string(", ") + CharacteristicName(spec.characteristic)) +
                  ", Omega " + std::to_string(static_cast<int>(std::lround(spec.rim_omega_deg))) + " / Theta " +
                  std::to_string(static_cast<int>(std::lround(spec.rim_theta_deg))) + " deg at the rim";
  drawing.notes = {lens_note, "Full table (" + std::to_string(r.profile.radius_mm.size()) +
                                  " rows): profile.csv; the model: sensor.yaml."};
  WriteProfileDrawing(drawing, InDir(dir, "profile_drawing.svg"), InDir(dir, "profile_drawing.png"));

  // h vs Omega (the seed's Fig. 5) and each curve's departure from the fitted law.
  PlotPanel height("Image height h vs Omega (seed Fig. 5)", "Omega (deg)", "h (px)");
  PlotPanel deviation(std::string("Departure from the ") + CharacteristicName(r.law) + " law", "Omega (deg)",
                      "h - h_law (px)");
  height.series.push_back(Curve("fitted " + std::string(spec.profile), r.achieved, 0, false, r.law));
  deviation.series.push_back(Curve("fitted", r.achieved, 0, true, r.law));
  if (r.compared) {
    height.series.push_back(Curve("compared: " + std::filesystem::path(r.compared_source).filename().string(),
                                  *r.compared, 1, false, r.law));
    deviation.series.push_back(Curve("compared", *r.compared, 1, true, r.law));
  }
  WritePng(InDir(dir, "characteristic.png"),
           TilePanels({RenderPanel(height, 700, 450), RenderPanel(deviation, 700, 450)}, 2));
}

}  // namespace omnical

#include "calib/report/optics_figures.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "calib/report/plot.h"

namespace omnical {
namespace {

constexpr double kDeg = 180.0 / M_PI;

std::vector<double> Column(const std::vector<FieldSample>& field, double (*get)(const FieldSample&)) {
  std::vector<double> out;
  for (const FieldSample& f : field) out.push_back(get(f));
  return out;
}

std::vector<double> OmegaDeg(const std::vector<FieldSample>& field) {
  return Column(field, [](const FieldSample& f) { return f.ray.omega_rad * kDeg; });
}

PlotSeries Line(std::string label, std::vector<double> x, std::vector<double> y, int color, bool dashed = false) {
  PlotSeries s{std::move(label), std::move(x), std::move(y), SeriesColor(color)};
  s.dashed = dashed;
  return s;
}

}  // namespace

void WriteCharacterizeFigures(const CharacterizeResult& result, const std::string& out_dir) {
  const std::filesystem::path dir(out_dir);
  const std::vector<FieldSample>& field = result.field;
  const BlurSettings& lens = result.lens;
  const double focus_mm = result.focus_mm, depth_of_field_mm = result.depth_of_field_mm;
  const std::vector<double> omega = OmegaDeg(field);
  const double rim = result.rim_radius_mm, m_mm = result.m_mm;

  // Fig. 4: the cross-section with rays every 15 deg of Omega, the virtual image points
  // (tangential T, sagittal S; object at infinity and at near_n mirror radii) and the
  // depth of field around the best focus.
  {
    PlotPanel panel{"Ray trace, virtual images and depth of field (seed Fig. 4)", "x (mm)", "z (mm, mirror frame)"};
    std::vector<double> profile_x, profile_z;
    for (int i = -200; i <= 200; ++i) {
      const double x = rim * i / 200.0;
      const FieldSample& s = field[std::min<size_t>(field.size() - 1, std::abs(i) * (field.size() - 1) / 200)];
      profile_x.push_back(x);
      profile_z.push_back(std::abs(i) == 0 ? 0.0 : s.ray.z_mm);
    }
    panel.series.push_back(Line("mirror", profile_x, profile_z, 7));
    for (double target = 15.0; target <= omega.back() + 1e-6; target += 15.0) {
      // The sample nearest each multiple of 15 deg of Omega.
      const size_t i =
          std::min_element(omega.begin(), omega.end(),
                           [&](double a, double b) { return std::abs(a - target) < std::abs(b - target); }) -
          omega.begin();
      const AxialRayQuantities& r = field[i].ray;
      const double down = -0.8 * rim;  // lens rays drawn from this height up to the mirror
      const double t = (down - r.z_mm) / std::cos(r.theta_rad);
      panel.series.push_back(
          Line(target == 15.0 ? "rays every 15 deg" : "",
               {r.x_mm + t * std::sin(r.theta_rad), r.x_mm, r.x_mm + 1.2 * rim * std::sin(r.omega_rad)},
               {down, r.z_mm, r.z_mm - 1.2 * rim * std::cos(r.omega_rad)}, 4));
      panel.series.back().thickness = 1;
    }
    auto points = [&](const char* label, int color, VirtualImage FieldSample::*which) {
      PlotSeries s{label, {}, {}, SeriesColor(color)};
      s.markers_only = true;
      for (size_t i = 0; i < field.size(); i += std::max<size_t>(1, field.size() / 40)) {
        s.x.push_back((field[i].*which).x_mm);
        s.y.push_back((field[i].*which).z_mm);
      }
      panel.series.push_back(s);
    };
    points("T inf", 0, &FieldSample::tangential_far);
    points("S inf", 1, &FieldSample::sagittal_far);
    points("T near", 2, &FieldSample::tangential_near);
    points("S near", 3, &FieldSample::sagittal_near);
    if (std::isfinite(depth_of_field_mm)) {
      const double f2 = lens.lens_focal_mm * lens.lens_focal_mm, spread = lens.pixel_mm * lens.f_number * focus_mm;
      panel.bands.push_back(
          {f2 * focus_mm / (f2 + spread) - m_mm, f2 * focus_mm / (f2 - spread) - m_mm, "depth of field"});
    }
    panel.equal_aspect = true;
    panel.x_range = std::make_pair(-1.3 * rim, 1.3 * rim);
    WritePng((dir / "fig04_ray_trace.png").string(), RenderPanel(panel, 900, 800));
  }

  // Fig. 5: h and dh/dOmega; per azimuth too when the sensor is tilted/decentred.
  {
    PlotPanel h{"Radial image height (seed Fig. 5)", "Omega (deg)", "h (px)"};
    PlotPanel dh{"Rate of change dh/dOmega (seed Fig. 5)", "Omega (deg)", "dh/dOmega (px/deg)"};
    h.series.push_back(
        Line(result.axial ? "h" : "aligned", omega, Column(field, [](const FieldSample& f) { return f.h_px; }), 0));
    dh.series.push_back(Line(result.axial ? "dh/dOmega" : "aligned", omega,
                             Column(field, [](const FieldSample& f) { return f.delta_h_px; }), 0));
    for (int k = 0; k < static_cast<int>(result.azimuth_curves.size()); ++k) {
      const std::vector<AzimuthSample>& curve = result.azimuth_curves[k];
      std::vector<double> om, hp, slope;
      for (size_t i = 0; i < curve.size(); ++i) {
        om.push_back(curve[i].omega_rad * kDeg);
        hp.push_back(curve[i].h_px);
        // Near the vertex a tilted mirror's Omega is not monotone along an azimuth (the
        // vertex ray leaves ~2 tilt off the axis), so dh/dOmega is singular there.
        const size_t a = i == 0 ? 0 : i - 1, b = std::min(i + 1, curve.size() - 1);
        slope.push_back(om.back() < 5.0
                            ? NAN
                            : (curve[b].h_px - curve[a].h_px) / ((curve[b].omega_rad - curve[a].omega_rad) * kDeg));
      }
      const std::string label = "azimuth " + std::to_string(90 * k) + " deg";
      h.series.push_back(Line(label, om, hp, k + 1, true));
      dh.series.push_back(Line(label, om, slope, k + 1, true));
    }
    const std::vector<double>& aligned_slope = dh.series.front().y;
    dh.y_range = std::make_pair(0.0, 1.3 * *std::max_element(aligned_slope.begin(), aligned_slope.end()));
    WritePng((dir / "fig05_image_height.png").string(),
             TilePanels({RenderPanel(h, 700, 500), RenderPanel(dh, 700, 500)}, 2));
  }

  // Fig. 6: viewpoint distribution, and the caustic in the cross-section.
  {
    PlotPanel panel{"Viewpoint distribution, Eq. 6 (seed Fig. 6)", "Omega (deg)", "z_v (mm, mirror frame)"};
    panel.series.push_back(
        Line("z_v", omega, Column(field, [](const FieldSample& f) { return f.ray.viewpoint_z_mm; }), 0));
    PlotPanel caustic{"Caustic (envelope of the object rays)", "x (mm)", "z (mm, mirror frame)"};
    caustic.series.push_back(Line("caustic", Column(field, [](const FieldSample& f) { return f.caustic_x_mm; }),
                                  Column(field, [](const FieldSample& f) { return f.caustic_z_mm; }), 1));
    caustic.series.push_back(Line("viewpoints on the axis", std::vector<double>(field.size(), 0.0),
                                  Column(field, [](const FieldSample& f) { return f.ray.viewpoint_z_mm; }), 0));
    caustic.series.back().markers_only = true;
    caustic.equal_aspect = true;
    WritePng((dir / "fig06_viewpoints.png").string(),
             TilePanels({RenderPanel(panel, 700, 500), RenderPanel(caustic, 700, 500)}, 2));
  }

  // Fig. 7: area and aspect ratio of a 1 x 1 deg object.
  {
    PlotPanel area{"Image area of a 1 x 1 deg object (seed Fig. 7)", "Omega (deg)", "delta_s (px^2)"};
    PlotPanel aspect{"Width-to-height ratio (seed Fig. 7)", "Omega (deg)", "delta_w / delta_h"};
    area.series.push_back(Line("delta_s", omega, Column(field, [](const FieldSample& f) { return f.delta_s_px2; }), 0));
    aspect.series.push_back(
        Line("delta_w / delta_h", omega, Column(field, [](const FieldSample& f) { return f.aspect_ratio; }), 1));
    WritePng((dir / "fig07_area_aspect.png").string(),
             TilePanels({RenderPanel(area, 700, 500), RenderPanel(aspect, 700, 500)}, 2));
  }

  // Fig. 8: image-forming characteristics: where a 15 x 15 deg grid of the viewing
  // sphere lands in the omni image (circles of constant Omega, azimuth spokes).
  {
    PlotPanel panel{"Image of a 15 x 15 deg grid on the viewing sphere (seed Fig. 8)", "u - cx (px)", "v - cy (px)"};
    auto h_at = [&](double omega_deg) {
      for (size_t i = 1; i < field.size(); ++i)
        if (omega[i] >= omega_deg) {
          const double t = (omega_deg - omega[i - 1]) / (omega[i] - omega[i - 1]);
          return field[i - 1].h_px + t * (field[i].h_px - field[i - 1].h_px);
        }
      return field.back().h_px;
    };
    const double max_omega = omega.back();
    for (double om = 15.0; om <= max_omega + 1e-6; om += 15.0) {
      std::vector<double> x, y;
      for (int k = 0; k <= 360; ++k)
        x.push_back(h_at(om) * std::cos(k * M_PI / 180)), y.push_back(h_at(om) * std::sin(k * M_PI / 180));
      panel.series.push_back(Line(om == 15.0 ? "Omega = 15, 30, ... deg" : "", x, y, 0));
    }
    for (int az = 0; az < 360; az += 15) {
      const double c = std::cos(az * M_PI / 180), s = std::sin(az * M_PI / 180);
      panel.series.push_back(Line(az == 0 ? "azimuth every 15 deg" : "", {h_at(1.0) * c, field.back().h_px * c},
                                  {h_at(1.0) * s, field.back().h_px * s}, 1));
      panel.series.back().thickness = 1;
    }
    panel.equal_aspect = true;
    WritePng((dir / "fig08_image_forming.png").string(), RenderPanel(panel, 800, 800));
  }

  // Fig. 9: blur spots at the chosen focus.
  {
    std::vector<double> t_px, s_px, t_deg, s_deg, area;
    for (const BlurSpot& b : result.blur) {
      t_px.push_back(b.tangential_px), s_px.push_back(b.sagittal_px);
      t_deg.push_back(b.tangential_deg), s_deg.push_back(b.sagittal_deg), area.push_back(b.area_deg2);
    }
    char title[120];
    std::snprintf(title, sizeof title, "Blur spot, pixels (L0 = %.1f mm, f = %.2f mm, F = %.1f)", focus_mm,
                  lens.lens_focal_mm, lens.f_number);
    PlotPanel px{title, "Omega (deg)", "blur (px, signed)"};
    px.series = {Line("tangential", omega, t_px, 0), Line("sagittal", omega, s_px, 1)};
    PlotPanel deg{"Blur spot in object space (seed Fig. 9b)", "Omega (deg)", "blur (deg)"};
    deg.series = {Line("tangential", omega, t_deg, 0), Line("sagittal", omega, s_deg, 1)};
    PlotPanel sq{"Blur-spot solid angle (seed Fig. 9c)", "Omega (deg)", "blur area (deg^2)"};
    sq.series = {Line("area", omega, area, 2)};
    WritePng((dir / "fig09_blur.png").string(),
             TilePanels({RenderPanel(px, 620, 460), RenderPanel(deg, 620, 460), RenderPanel(sq, 620, 460)}, 3));
  }
}

}  // namespace omnical

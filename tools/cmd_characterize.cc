// omnical characterize: the seed paper's evaluation of a sensor (Ohte & Tsuzuki Secs.
// 2-3 and appendix): image-forming characteristics, viewpoints, virtual images, blur
// and depth of field, as CSV, summary.json and figures in the spirit of Figs. 4-9.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <optional>
#include <ostream>

#include "model/atomic_write.h"
#include "model/input_error.h"
#include "model/optics.h"
#include "tools/commands.h"
#include "calib/report/plot.h"

namespace omnical::cli {
namespace {

constexpr double kDeg = 180.0 / M_PI;

struct Options {
  std::string sensor_path, out_dir;
  std::optional<double> lens_focal_mm, focus_mm;
  double f_number = 4.0, pixel_um = 5.2, near_n = 5.0;
  int samples = 540;
};

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

void WriteFigures(const Options& options, const Sensor& sensor, const std::vector<FieldSample>& field,
                  const BlurSettings& lens, double focus_mm, double depth_of_field_mm) {
  const std::filesystem::path dir(options.out_dir);
  const std::vector<double> omega = OmegaDeg(field);
  const double rim = sensor.rim_radius_mm();
  double m_mm = 0.0;
  std::visit([&](const auto& model) { m_mm = model.pose.m_mm; }, sensor.model());

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
      const size_t i = std::min_element(omega.begin(), omega.end(), [&](double a, double b) {
                         return std::abs(a - target) < std::abs(b - target);
                       }) - omega.begin();
      const AxialRayQuantities& r = field[i].ray;
      const double down = -0.8 * rim;  // lens rays drawn from this height up to the mirror
      const double t = (down - r.z_mm) / std::cos(r.theta_rad);
      panel.series.push_back(Line(target == 15.0 ? "rays every 15 deg" : "", {r.x_mm + t * std::sin(r.theta_rad), r.x_mm,
                                   r.x_mm + 1.2 * rim * std::sin(r.omega_rad)},
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
      panel.bands.push_back({f2 * focus_mm / (f2 + spread) - m_mm, f2 * focus_mm / (f2 - spread) - m_mm,
                             "depth of field"});
    }
    panel.equal_aspect = true;
    panel.x_range = std::make_pair(-1.3 * rim, 1.3 * rim);
    WritePng((dir / "fig04_ray_trace.png").string(), RenderPanel(panel, 900, 800));
  }

  // Fig. 5: h and dh/dOmega; per azimuth too when the sensor is tilted/decentred.
  {
    PlotPanel h{"Radial image height (seed Fig. 5)", "Omega (deg)", "h (px)"};
    PlotPanel dh{"Rate of change dh/dOmega (seed Fig. 5)", "Omega (deg)", "dh/dOmega (px/deg)"};
    h.series.push_back(Line(sensor.is_axial() ? "h" : "aligned", omega, Column(field, [](const FieldSample& f) { return f.h_px; }), 0));
    dh.series.push_back(Line(sensor.is_axial() ? "dh/dOmega" : "aligned", omega,
                             Column(field, [](const FieldSample& f) { return f.delta_h_px; }), 0));
    if (!sensor.is_axial()) {
      for (int k = 0; k < 4; ++k) {
        const std::vector<AzimuthSample> curve = ExactAzimuthCurve(sensor, k * M_PI / 2.0, options.samples);
        std::vector<double> om, hp, slope;
        for (size_t i = 0; i < curve.size(); ++i) {
          om.push_back(curve[i].omega_rad * kDeg);
          hp.push_back(curve[i].h_px);
          // Near the vertex a tilted mirror's Omega is not monotone along an azimuth (the
          // vertex ray leaves ~2 tilt off the axis), so dh/dOmega is singular there.
          const size_t a = i == 0 ? 0 : i - 1, b = std::min(i + 1, curve.size() - 1);
          slope.push_back(om.back() < 5.0 ? NAN
                                          : (curve[b].h_px - curve[a].h_px) /
                                                ((curve[b].omega_rad - curve[a].omega_rad) * kDeg));
        }
        const std::string label = "azimuth " + std::to_string(90 * k) + " deg";
        h.series.push_back(Line(label, om, hp, k + 1, true));
        dh.series.push_back(Line(label, om, slope, k + 1, true));
      }
    }
    const std::vector<double>& aligned_slope = dh.series.front().y;
    dh.y_range = std::make_pair(0.0, 1.3 * *std::max_element(aligned_slope.begin(), aligned_slope.end()));
    WritePng((dir / "fig05_image_height.png").string(), TilePanels({RenderPanel(h, 700, 500), RenderPanel(dh, 700, 500)}, 2));
  }

  // Fig. 6: viewpoint distribution, and the caustic in the cross-section.
  {
    PlotPanel panel{"Viewpoint distribution, Eq. 6 (seed Fig. 6)", "Omega (deg)", "z_v (mm, mirror frame)"};
    panel.series.push_back(Line("z_v", omega, Column(field, [](const FieldSample& f) { return f.ray.viewpoint_z_mm; }), 0));
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
    aspect.series.push_back(Line("delta_w / delta_h", omega, Column(field, [](const FieldSample& f) { return f.aspect_ratio; }), 1));
    WritePng((dir / "fig07_area_aspect.png").string(), TilePanels({RenderPanel(area, 700, 500), RenderPanel(aspect, 700, 500)}, 2));
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
      for (int k = 0; k <= 360; ++k) x.push_back(h_at(om) * std::cos(k * M_PI / 180)), y.push_back(h_at(om) * std::sin(k * M_PI / 180));
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
    for (const FieldSample& f : field) {
      const BlurSpot b = BlurAt(f, lens, focus_mm);
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

void Run(const Options& options, const Context& context) {
  const Sensor sensor = LoadSensorYaml(options.sensor_path);
  if (const std::string why = RimOutsideImage(sensor); !why.empty())
    throw InputError(InputMessage(options.sensor_path, "", why));
  CreateOutputDirectory(options.out_dir);
  const double rim = sensor.rim_radius_mm();
  const std::vector<FieldSample> field = AnalyzeField(sensor, options.samples, options.near_n * rim);

  BlurSettings lens;
  lens.f_number = options.f_number;
  lens.pixel_mm = options.pixel_um * 1e-3;
  // Default focal length: the sensor's own, fx in mm on this pixel pitch.
  std::visit(
      [&](const auto& model) {
        if constexpr (std::decay_t<decltype(model)>::kOrthographic) {
          lens.lens_focal_mm = options.lens_focal_mm.value_or(0.0);
        } else {
          lens.lens_focal_mm = options.lens_focal_mm.value_or(model.lens.fx_px * lens.pixel_mm);
        }
      },
      sensor.model());
  if (!(lens.lens_focal_mm > 0.0))
    throw InputError("--lens-f: an orthographic sensor has no focal length of its own; give --lens-f (mm)");
  double mean_blur_area = 0.0;
  const double focus_mm = options.focus_mm ? *options.focus_mm : BestFocusDistanceMm(field, lens, &mean_blur_area);
  if (options.focus_mm) mean_blur_area = MeanBlurAreaDeg2(field, lens, focus_mm);
  const double dof_mm = DepthOfFieldMm(lens, focus_mm);

  double caustic_x = 0.0, caustic_z_lo = HUGE_VAL, caustic_z_hi = -HUGE_VAL;
  for (const FieldSample& f : field) {
    caustic_x = std::max(caustic_x, std::abs(f.caustic_x_mm));
    caustic_z_lo = std::min(caustic_z_lo, f.caustic_z_mm), caustic_z_hi = std::max(caustic_z_hi, f.caustic_z_mm);
  }
  double z_lo = HUGE_VAL, z_hi = -HUGE_VAL, astigmatism = 0.0, worst_blur = 0.0, slope_lo = HUGE_VAL, slope_hi = 0.0;
  for (const FieldSample& f : field) {
    z_lo = std::min(z_lo, f.ray.viewpoint_z_mm), z_hi = std::max(z_hi, f.ray.viewpoint_z_mm);
    astigmatism = std::max(astigmatism, std::abs(f.tangential_far.lens_distance_mm - f.sagittal_far.lens_distance_mm));
    const BlurSpot b = BlurAt(f, lens, focus_mm);
    worst_blur = std::max({worst_blur, std::abs(b.tangential_px), std::abs(b.sagittal_px)});
    slope_lo = std::min(slope_lo, f.delta_h_px), slope_hi = std::max(slope_hi, f.delta_h_px);
  }

  WriteOutput((std::filesystem::path(options.out_dir) / "characteristics.csv").string(), [&](std::ostream& out) {
    out << "x_mm,z_mm,omega_deg,theta_deg,beta_deg,gamma_deg,viewpoint_z_mm,h_px,dh_domega_px_per_deg,"
           "delta_w_px,delta_s_px2,aspect_ratio,tangential_curvature_per_mm,sagittal_curvature_per_mm,"
           "t_inf_x_mm,t_inf_z_mm,s_inf_x_mm,s_inf_z_mm,t_near_x_mm,t_near_z_mm,s_near_x_mm,s_near_z_mm,"
           "L_t_inf_mm,L_s_inf_mm,blur_t_px,blur_s_px,blur_t_deg,blur_s_deg,blur_area_deg2,caustic_x_mm,caustic_z_mm\n"
        << std::setprecision(10);
    for (const FieldSample& f : field) {
      const BlurSpot b = BlurAt(f, lens, focus_mm);
      const AxialRayQuantities& r = f.ray;
      out << r.x_mm << ',' << r.z_mm << ',' << r.omega_rad * kDeg << ',' << r.theta_rad * kDeg << ','
          << r.beta_rad * kDeg << ',' << r.gamma_rad * kDeg << ',' << r.viewpoint_z_mm << ',' << f.h_px << ','
          << f.delta_h_px << ',' << f.delta_w_px << ',' << f.delta_s_px2 << ',' << f.aspect_ratio << ','
          << f.tangential_curvature_per_mm << ',' << f.sagittal_curvature_per_mm << ',' << f.tangential_far.x_mm
          << ',' << f.tangential_far.z_mm << ',' << f.sagittal_far.x_mm << ',' << f.sagittal_far.z_mm << ','
          << f.tangential_near.x_mm << ',' << f.tangential_near.z_mm << ',' << f.sagittal_near.x_mm << ','
          << f.sagittal_near.z_mm << ',' << f.tangential_far.lens_distance_mm << ','
          << f.sagittal_far.lens_distance_mm << ',' << b.tangential_px << ',' << b.sagittal_px << ','
          << b.tangential_deg << ',' << b.sagittal_deg << ',' << b.area_deg2 << ',' << f.caustic_x_mm << ','
          << f.caustic_z_mm << '\n';
    }
  });

  nlohmann::json summary;
  summary["sensor"] = options.sensor_path;
  summary["profile"] = sensor.profile_name();
  summary["lens"] = sensor.lens_name();
  summary["analysed_as"] = sensor.is_axial() ? "axial" : "aligned counterpart (tilt and decenter set to 0); "
                                                         "fig05 adds the exact curves per azimuth";
  summary["samples"] = options.samples;
  summary["rim_omega_deg"] = field.back().ray.omega_rad * kDeg;
  summary["rim_theta_deg"] = field.back().ray.theta_rad * kDeg;
  summary["rim_h_px"] = field.back().h_px;
  summary["viewpoint_spread_mm"] = z_hi - z_lo;
  summary["viewpoint_range_mm"] = {z_lo, z_hi};
  summary["caustic_extent_mm"] = {{"radial", caustic_x}, {"axial", caustic_z_hi - caustic_z_lo}};
  summary["max_astigmatism_mm"] = astigmatism;
  summary["dh_domega_px_per_deg"] = {{"min", slope_lo}, {"max", slope_hi}, {"at_rim", field.back().delta_h_px}};
  summary["lens_focal_mm"] = lens.lens_focal_mm;
  summary["f_number"] = lens.f_number;
  summary["pixel_um"] = options.pixel_um;
  summary["near_distance_mm"] = options.near_n * rim;
  summary["best_L0_mm"] = focus_mm;
  summary["L0_searched"] = !options.focus_mm.has_value();
  summary["depth_of_field_mm"] = std::isfinite(dof_mm) ? nlohmann::json(dof_mm) : nlohmann::json(nullptr);
  summary["mean_blur_area_deg2"] = mean_blur_area;
  summary["worst_blur_px"] = worst_blur;
  summary["mean_solid_angle_per_pixel_deg2"] = MeanSolidAnglePerPixelDeg2(field);
  WriteOutput((std::filesystem::path(options.out_dir) / "summary.json").string(),
              [&](std::ostream& out) { out << summary.dump(2) << '\n'; });
  WriteFigures(options, sensor, field, lens, focus_mm, dof_mm);
  if (!context.quiet)
    std::printf("%s: rim Omega %.2f deg, Theta %.2f deg; viewpoint spread %.3g mm; best L0 %.1f mm, depth of field "
                "%.2f mm, worst blur %.2f px -> %s\n",
                options.sensor_path.c_str(), field.back().ray.omega_rad * kDeg, field.back().ray.theta_rad * kDeg,
                z_hi - z_lo, focus_mm, dof_mm, worst_blur, options.out_dir.c_str());
}

}  // namespace

Command CharacterizeCommand() {
  return {"characterize",
          "The seed paper's evaluation of a sensor: characteristics, viewpoints, virtual images, blur, depth of field",
          [](CLI::App& sub, const Context& context) -> CommandAction {
            auto options = std::make_shared<Options>();
            sub.add_option("--sensor", options->sensor_path, "Sensor file (YAML)")->required();
            sub.add_option("--out", options->out_dir, "Output directory (CSV, summary.json, PNG figures)")->required();
            sub.add_option("--lens-f", options->lens_focal_mm, "Lens focal length, mm (default: fx x pixel size)")
                ->check(kPositive);
            sub.add_option("--f-number", options->f_number, "Lens f-number F")->check(kPositive)->capture_default_str();
            sub.add_option("--pixel-um", options->pixel_um, "Pixel size, um (the permissible circle of confusion)")
                ->check(kPositive)->capture_default_str();
            sub.add_option("--focus-mm", options->focus_mm, "In-focus distance L0, mm (default: searched)")
                ->check(kPositive);
            sub.add_option("--near-n", options->near_n, "Near object distance for virtual images, mirror radii")
                ->check(kPositive)->capture_default_str();
            sub.add_option("--samples", options->samples, "Samples over the mirror radius")
                ->check(CLI::Range(10, 100000))->capture_default_str();
            return [options, &context]() { Run(*options, context); };
          }};
}

}  // namespace omnical::cli

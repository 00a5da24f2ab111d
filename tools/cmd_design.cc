// omnical design ode: a mirror profile from Gächter's reflection ODE for an imaging law,
// written as a tabulated sensor every other subcommand takes, with the design's field of
// view, the law checked through omnical's own ray tracing, and the seed's distance
// sensitivity (Figs. 9, 10, 14).
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <optional>

#include "model/atomic_write.h"
#include "model/design_spec_yaml.h"
#include "model/designed_sensor.h"
#include "model/input_error.h"
#include "model/mirror_design_ode.h"
#include "tools/cmd_design_fit.h"
#include "tools/commands.h"
#include "calib/report/plot.h"
#include "calib/report/profile_drawing.h"

namespace omnical::cli {
namespace {

struct OdeOptions {
  std::string spec_path, law, law_table, out_dir;
  double focal_length_mm = 0.0, distance_mm = 0.0, start_height_mm = 0.0, rim_limit_mm = 0.0;
  double rho0_mm = 0.0, rho1_mm = 0.0, gain = 0.0, offset_mm = 0.0, growth_rate = 0.0;
  int samples = 20001, image_size_px = 1000;
};

// Cylinders the seed checks its designs on: 1, 1.5, 2, 3 and 4 m for d = 2 m.
constexpr double kDistanceFactors[] = {0.5, 0.75, 1.0, 1.5, 2.0};
// Intervals of rho for the law ratio: 1 % of the imager each (the seed's Fig. 10 smooths
// its finite differences instead).
constexpr int kRatioIntervals = 100;

OdeDesignSpec SpecFromOptions(const OdeOptions& o) {
  if (!o.spec_path.empty()) return LoadOdeDesignSpec(o.spec_path);
  OdeDesignSpec spec;
  spec.focal_length_mm = o.focal_length_mm;
  spec.distance_mm = o.distance_mm;
  spec.start_height_mm = o.start_height_mm;
  spec.rim_limit_mm = o.rim_limit_mm;
  spec.rho0_mm = o.rho0_mm;
  spec.rho1_mm = o.rho1_mm;
  if (o.law == "linear") {
    spec.law.kind = ImagingLaw::Kind::kLinear;
  } else if (o.law == "logpolar") {
    spec.law.kind = ImagingLaw::Kind::kLogPolar;
    spec.law.rho0_mm = o.rho0_mm;
    spec.law.growth_rate = o.growth_rate;
  } else {
    if (o.law_table.empty()) throw InputError("--law table needs --law-table FILE (rows rho_mm, h_mm)");
    LoadLawTable(o.law_table, &spec.law);
  }
  spec.law.gain = o.gain;
  spec.law.offset_mm = o.offset_mm;
  if (const std::string why = spec.Check(); !why.empty()) throw InputError("design ode: " + why);
  return spec;
}

void RunOde(const OdeOptions& options, const Context& context) {
  const OdeDesignSpec spec = SpecFromOptions(options);
  const OdeDesign design = SolveMirrorOde(spec, options.samples);
  const std::filesystem::path dir(options.out_dir);
  CreateOutputDirectory(dir);
  const double vertex_mm = design.profile.front().height_mm;

  ProfileDrawing drawing;  // the profile from the vertex: profile.csv, the figures, the drawing
  for (const ProfileSample& s : design.profile) {
    drawing.radius_mm.push_back(s.radius_mm);
    drawing.sag_mm.push_back(s.height_mm - vertex_mm);
    drawing.slope.push_back(s.slope);
  }
  WriteProfileTable(drawing, "design ode", (dir / "profile.csv").string());
  const Sensor sensor = SensorFromOdeDesign(spec, design, options.image_size_px, (dir / "profile.csv").string());
  const double pitch_mm = PixelPitchMm(design, options.image_size_px);
  const auto& lens = std::get<Catadioptric<double, TabulatedProfile, PinholeLens>>(sensor.model()).lens;
  WriteFileAtomically((dir / "sensor.yaml").string(), [&](std::ostream& out) {
    out << std::setprecision(15) << "# Designed by omnical design ode (Gächter's reflection ODE); pixel pitch " << pitch_mm * 1e3
        << " um puts the field's end at 0.49 image widths.\n"
        << "camera: { model: pinhole, image_size: [" << options.image_size_px << ", " << options.image_size_px
        << "], fx: " << lens.fx_px << ", fy: " << lens.fy_px << ", cx: " << lens.cx_px << ", cy: " << lens.cy_px
        << ", k1: 0, k2: 0 }\n"
        << "mirror: { profile: tabulated, rim_radius: " << design.t_end_mm << ", table: profile.csv }\n"
        << "pose:   { m: " << vertex_mm - spec.focal_length_mm << ", tilt_deg: [0, 0], decenter_mm: [0, 0] }\n";
  });

  // The law through omnical's own ray tracing of the written sensor, at d and around it.
  // With rho0 = 0 the centre pixel looks back along the axis at the mirror's tip (the
  // ODE gives it a cusp, slope != 0): the check starts 0.1 % of the field out.
  const double rho_from_mm = spec.rho0_mm > 0.0 ? spec.rho0_mm : 1e-3 * design.rho_end_mm;
  std::vector<LawRatioCurve> curves;
  for (double factor : kDistanceFactors)
    curves.push_back(TraceLawRatio(sensor, spec, pitch_mm, factor * spec.distance_mm, rho_from_mm, design.rho_end_mm,
                                   kRatioIntervals));
  const LawRatioCurve& reference = curves[2];
  double worst = 0.0;  // HUGE_VAL where a ray missed
  for (double r : reference.ratio) worst = std::isfinite(r) ? std::max(worst, std::abs(r - 1.0)) : HUGE_VAL;

  nlohmann::json j;
  j["phi0_deg"] = design.phi0_deg;
  j["phi1_deg"] = design.phi1_deg;
  j["fov_deg"] = design.phi1_deg - design.phi0_deg;
  j["max_law_error_rel"] = std::isfinite(worst) ? nlohmann::json(worst) : nlohmann::json("ray missed");
  j["max_law_error_meaning"] =
      "max |ratio - 1| at the reference distance, ratio = traced increment of h over the law's increment, on 100 "
      "intervals of rho from rho0 (0.1 % of the field where rho0 = 0: the tip) to the field's end; rays traced by "
      "omnical through sensor.yaml";
  j["field"] = {{"t_start_mm", design.t_start_mm},
                {"t_end_mm", design.t_end_mm},
                {"rho_end_mm", design.rho_end_mm},
                {"ends_at", design.ended_at_rim ? "mirror rim (t1), inside rho1" : "imager limit rho1"}};
  j["ode"] = {{"solver", "Boost.Odeint runge_kutta_dopri5, dense output"}, {"tolerance_rel", 1e-13}, {"steps", design.ode_steps},
              {"profile_samples", design.profile.size()}};
  j["sensor"] = {{"file", "sensor.yaml"}, {"m_mm", vertex_mm - spec.focal_length_mm}, {"pixel_pitch_mm", pitch_mm}};
  nlohmann::json sensitivity = nlohmann::json::array();
  for (const LawRatioCurve& c : curves) {
    const auto [lo, hi] = std::minmax_element(c.ratio.begin(), c.ratio.end());
    sensitivity.push_back({{"distance_mm", c.distance_mm}, {"ratio_min", *lo}, {"ratio_max", *hi}});
  }
  j["distance_sensitivity"] = sensitivity;
  WriteFileAtomically((dir / "law_ratio.csv").string(), [&](std::ostream& out) {
    out << "rho_mm";
    for (const LawRatioCurve& c : curves) out << ",ratio_at_" << c.distance_mm << "_mm";
    out << '\n' << std::setprecision(12);
    for (size_t i = 0; i < reference.rho_mm.size(); ++i) {
      out << reference.rho_mm[i];
      for (const LawRatioCurve& c : curves) out << ',' << c.ratio[i];
      out << '\n';
    }
  });

  // Figures: the law ratio (Figs. 10, 14), the profile, and the ray diagram (Fig. 8).
  PlotPanel ratio("Imaging law through the designed mirror (1 = the law, scaled by distance / d)", "rho (mm)",
                  "traced dh / law dh, / (d_i / d)");
  for (size_t k = 0; k < curves.size(); ++k) {
    char label[64];
    std::snprintf(label, sizeof label, "cylinder at %.0f mm%s", curves[k].distance_mm, k == 2 ? " (design)" : "");
    ratio.series.emplace_back(label, curves[k].rho_mm, curves[k].ratio, SeriesColor(static_cast<int>(k)));
  }
  PlotPanel profile("Mirror profile", "x (mm)", "sag z (mm)");
  profile.equal_aspect = true;
  profile.series.emplace_back("profile", drawing.radius_mm, drawing.sag_mm, SeriesColor(0));
  PlotPanel rays("Rays: image -> pinhole -> mirror -> reference cylinder", "radius (mm)", "height above the image plane (mm)");
  for (int i = 0; i <= 12; ++i) {
    const double rho = spec.rho0_mm + (design.rho_end_mm - spec.rho0_mm) * i / 12.0;
    // The mirror point of rho: on the profile where f t / (F - f) = rho.
    const auto it = std::lower_bound(design.profile.begin(), design.profile.end(), rho, [&](const ProfileSample& s, double r) {
      return spec.focal_length_mm * s.radius_mm / (s.height_mm - spec.focal_length_mm) < r;
    });
    if (it == design.profile.end()) continue;
    const double h = TracedHeightMm(sensor, spec, pitch_mm, rho, spec.distance_mm);
    rays.series.emplace_back("", std::vector<double>{-rho, 0.0, it->radius_mm, spec.distance_mm},
                             std::vector<double>{0.0, spec.focal_length_mm, it->height_mm, h}, cv::Scalar(160, 160, 160));
    rays.series.back().thickness = 1;
  }
  rays.series.emplace_back("mirror", drawing.radius_mm, std::vector<double>(), SeriesColor(1));
  for (const ProfileSample& s : design.profile) rays.series.back().y.push_back(s.height_mm);
  WritePng((dir / "law_ratio.png").string(), RenderPanel(ratio, 900, 500));
  WritePng((dir / "profile.png").string(), TilePanels({RenderPanel(profile, 700, 450), RenderPanel(rays, 700, 450)}, 2));
  const char* law_name = spec.law.kind == ImagingLaw::Kind::kLinear     ? "linear"
                         : spec.law.kind == ImagingLaw::Kind::kLogPolar ? "log-polar"
                                                                        : "tabulated";
  char title[160], lens_note[200], plane_note[120];
  std::snprintf(title, sizeof title, "omnical design ode: %s law on a cylinder at d = %.0f mm", law_name, spec.distance_mm);
  std::snprintf(lens_note, sizeof lens_note, "Pinhole (f = %.3f mm) %.3f mm below the vertex (m),", spec.focal_length_mm,
                vertex_mm - spec.focal_length_mm);
  drawing.title = title;
  std::snprintf(plane_note, sizeof plane_note, "image plane %.3f mm below the vertex (F0).", vertex_mm);
  drawing.notes = {lens_note, plane_note, "Full table: profile.csv; the model: sensor.yaml."};
  WriteProfileDrawing(drawing, (dir / "profile_drawing.svg").string(), (dir / "profile_drawing.png").string());
  WriteFileAtomically((dir / "design.json").string(), [&](std::ostream& out) { out << j.dump(2) << '\n'; });

  if (!context.quiet)
    std::printf("phi0 %.3f deg, phi1 %.3f deg, field of view %.3f deg (ends at %s); law through the traced sensor within "
                "%.2g relative -> %s\n",
                design.phi0_deg, design.phi1_deg, design.phi1_deg - design.phi0_deg,
                design.ended_at_rim ? "the mirror rim" : "rho1", worst, options.out_dir.c_str());
}

}  // namespace

Command DesignCommand() {
  return {"design", "Mirror design: the reflection ODE for an imaging law (ode), or a profile family fitted to rim targets (fit)",
          [](CLI::App& sub, const Context& context) -> CommandAction {
            auto options = std::make_shared<OdeOptions>();
            auto fit_options = std::make_shared<DesignFitOptions>();
            sub.require_subcommand(1);
            CLI::App* ode = sub.add_subcommand("ode", "Gächter's reflection ODE: a profile imaging a cylinder by a law h(rho)");
            auto* spec = ode->add_option("--spec", options->spec_path, "Design spec (YAML, see datasets-synthetic/designs)");
            auto* law = ode->add_option("--law", options->law, "Imaging law: linear, logpolar or table")
                            ->check(CLI::IsMember({"linear", "logpolar", "table"}));
            spec->excludes(law);
            ode->add_option("--focal-length-mm", options->focal_length_mm, "f: the pinhole's focal length (mm)");
            ode->add_option("--distance-mm", options->distance_mm, "d: the reference cylinder's radius (mm)");
            ode->add_option("--start-height-mm", options->start_height_mm, "F0: image plane to mirror vertex (mm)");
            ode->add_option("--rim-limit-mm", options->rim_limit_mm, "t1: the largest mirror radius (mm)");
            ode->add_option("--rho0-mm", options->rho0_mm, "Imager: innermost used radius (mm)");
            ode->add_option("--rho1-mm", options->rho1_mm, "Imager: outermost used radius (mm)");
            ode->add_option("--gain", options->gain, "Law gain a (linear: dimensionless; logpolar: mm)");
            ode->add_option("--offset-mm", options->offset_mm, "Law offset b (mm)");
            ode->add_option("--growth-rate", options->growth_rate, "logpolar: pixel growth rate k (> 1)");
            ode->add_option("--law-table", options->law_table, "table: CSV rows rho_mm, h_mm (strictly increasing)");
            ode->add_option("--samples", options->samples, "Profile samples written (uniform in x)")
                ->check(CLI::Range(100, 1000000))
                ->capture_default_str();
            ode->add_option("--image-size", options->image_size_px, "Square image of the designed sensor (px)")
                ->check(CLI::Range(64, 20000))
                ->capture_default_str();
            ode->add_option("--out", options->out_dir, "Output directory")->required();
            ode->callback([options, spec, law]() {
              if (spec->count() + law->count() == 0) throw CLI::RequiredError("--spec or --law");
            });
            CLI::App* fit = sub.add_subcommand("fit", "Ohte & Tsuzuki's design by parameters (Table 1), solved with Ceres");
            AddDesignFitOptions(fit, fit_options.get());
            return [options, fit_options, fit, &context]() {
              if (fit->parsed())
                RunDesignFit(*fit_options, context);
              else
                RunOde(*options, context);
            };
          }};
}

}  // namespace omnical::cli

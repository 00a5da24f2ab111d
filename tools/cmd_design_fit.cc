// omnical design fit: Ohte & Tsuzuki's design by parameters (Table 1) with Ceres: a sphere,
// even polynomial or hyperboloid whose rim ray has the target Omega and Theta, shaped for a
// characteristic; written as a sensor every other subcommand takes, with the image laws the
// design (and optionally another sensor file, for comparison) achieves.
#include "tools/cmd_design_fit.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iomanip>

#include "model/atomic_write.h"
#include "model/input_error.h"
#include "model/mirror_design_fit.h"
#include "model/ray_quantities.h"
#include "calib/report/plot.h"
#include "calib/report/profile_drawing.h"

namespace omnical::cli {
namespace {

// The achieved laws of one sensor, as design.json reports them.
nlohmann::json CharacteristicsJson(const CharacteristicReport& r) {
  return {{"rim_omega_deg", r.rim_omega_deg},
          {"rim_theta_deg", r.rim_theta_deg},
          {"rim_h_px", r.rim_h_px},
          {"equidistant_max_px", r.equidistant_max_px},
          {"constant_aspect_max_px", r.constant_aspect_max_px},
          {"equal_area_max_px", r.equal_area_max_px},
          {"viewpoint_spread_mm", r.viewpoint_spread_mm}};
}

// Table 1's names for the normalised parameters, and their lengths in mm.
nlohmann::json ParametersJson(const FitDesign& design, double rim_mm) {
  nlohmann::json normalised, mm;
  if (design.family == ProfileFamily::kPolynomial) {
    for (size_t k = 0; k < design.params.size(); ++k) {
      normalised["c" + std::to_string(k + 1)] = design.params[k];
      mm["c" + std::to_string(k + 1) + "_per_mm" + (k == 0 ? std::string() : std::to_string(2 * k + 1))] =
          design.params[k] / std::pow(rim_mm, 2.0 * k + 1.0);
    }
  } else {
    normalised["A"] = design.params[0];
    mm["A_mm"] = design.params[0] * rim_mm;
    if (design.family == ProfileFamily::kHyperboloid) {
      normalised["B"] = design.params[1];
      mm["B_mm"] = design.params[1] * rim_mm;
    }
  }
  normalised["m"] = design.m;
  mm["m_mm"] = design.m * rim_mm;
  mm["rim_radius_mm"] = rim_mm;
  return {{"normalised", normalised}, {"mm", mm}};
}

PlotSeries Curve(const std::string& label, const CharacteristicReport& r, int color, bool deviation, ImageCharacteristic law) {
  std::vector<double> omega, value;
  for (const CharacteristicSample& s : r.samples) {
    omega.push_back(s.omega_deg);
    const double h_law = r.rim_h_px * LawHeightRatio(law, s.omega_deg * M_PI / 180.0, r.rim_omega_deg * M_PI / 180.0);
    value.push_back(deviation ? s.h_px - h_law : s.h_px);
  }
  return PlotSeries(label, omega, value, SeriesColor(color));
}

}  // namespace

void AddDesignFitOptions(CLI::App* fit, DesignFitOptions* o) {
  fit->add_option("--profile", o->profile, "Profile family: sphere, polynomial or hyperboloid")
      ->required()
      ->check(CLI::IsMember({"sphere", "polynomial", "hyperboloid"}));
  fit->add_option("--terms", o->terms, "polynomial: even terms c1 x^2 .. cn x^2n")->check(CLI::Range(1, 8))->capture_default_str();
  fit->add_option("--rim-omega", o->rim_omega_deg, "Omega at the rim: the object ray's angle from the -z axis (deg)")
      ->capture_default_str();
  fit->add_option("--rim-theta", o->rim_theta_deg, "Theta at the rim: the lens's viewing angle (deg)")->capture_default_str();
  fit->add_option("--characteristic", o->characteristic,
                  "equidistant, svp, aspect or area (default: polynomial equidistant, hyperboloid svp; a sphere has no "
                  "freedom left)")
      ->check(CLI::IsMember({"equidistant", "svp", "aspect", "area"}));
  fit->add_option("--rim-radius-mm", o->rim_radius_mm, "Mirror radius M at the rim (mm): scales the normalised design")
      ->check(kPositive)
      ->capture_default_str();
  fit->add_option("--image-size", o->image_size_px, "Square image; the rim images at half its width (the paper's 2N)")
      ->check(CLI::Range(64, 20000))
      ->capture_default_str();
  fit->add_option("--compare", o->compare_path, "Another axial sensor file measured the same way (e.g. Table 1's)");
  fit->add_option("--out", o->out_dir, "Output directory")->required();
}

void RunDesignFit(const DesignFitOptions& o, const Context& context) {
  FitDesignSpec spec;
  spec.family = o.profile == "sphere" ? ProfileFamily::kSphere
                : o.profile == "hyperboloid" ? ProfileFamily::kHyperboloid
                                             : ProfileFamily::kPolynomial;
  spec.polynomial_terms = o.terms;
  spec.rim_omega_deg = o.rim_omega_deg;
  spec.rim_theta_deg = o.rim_theta_deg;
  const std::string characteristic =
      !o.characteristic.empty() ? o.characteristic
      : spec.family == ProfileFamily::kPolynomial && o.terms > 1 ? "equidistant"
      : spec.family == ProfileFamily::kHyperboloid ? "svp"
                                                   : "";
  for (ImageCharacteristic c : {ImageCharacteristic::kEquidistant, ImageCharacteristic::kSingleViewpoint,
                                 ImageCharacteristic::kConstantAspect, ImageCharacteristic::kEqualArea})
    if (characteristic == CharacteristicName(c)) spec.characteristic = c;
  // The comparison sensor is read before anything is written, so a bad file leaves no output.
  std::optional<CharacteristicReport> compared;
  constexpr int kSamples = 1000;
  if (!o.compare_path.empty()) {
    try {
      compared = MeasureCharacteristics(LoadSensorYaml(o.compare_path), kSamples);
    } catch (const InputError& e) {
      const std::string what = e.what();
      throw InputError(what.rfind(o.compare_path, 0) == 0 ? what : o.compare_path + ": " + what);
    }
  }

  const FitDesign design = FitMirrorDesign(spec);
  const Sensor sensor = SensorFromFitDesign(design, spec, o.rim_radius_mm, o.image_size_px);
  const CharacteristicReport achieved = MeasureCharacteristics(sensor, kSamples);
  const std::filesystem::path dir(o.out_dir);
  CreateOutputDirectory(dir);
  SaveSensorYaml(sensor, (dir / "sensor.yaml").string());

  // The profile in mm, and the drawing from it.
  ProfileDrawing drawing;
  std::visit(
      [&](const auto& model) {
        constexpr int kProfileSamples = 2000;
        for (int i = 0; i <= kProfileSamples; ++i) {
          const AxialRayQuantities q = ComputeAxialRay(model, o.rim_radius_mm * i / kProfileSamples);
          drawing.radius_mm.push_back(q.x_mm);
          drawing.sag_mm.push_back(q.z_mm);
          drawing.slope.push_back(std::tan(q.beta_rad));
        }
      },
      sensor.model());
  WriteProfileTable(drawing, "design fit", (dir / "profile.csv").string());
  char lens_note[160];
  std::snprintf(lens_note, sizeof lens_note, "Lens principal point on the axis %.3f mm below the vertex (m).",
                design.m * o.rim_radius_mm);
  drawing.title = std::string("omnical design fit: ") + ProfileFamilyName(spec.family) +
                  (characteristic.empty() ? std::string() : ", " + characteristic) + ", Omega " +
                  std::to_string(static_cast<int>(std::lround(spec.rim_omega_deg))) + " / Theta " +
                  std::to_string(static_cast<int>(std::lround(spec.rim_theta_deg))) + " deg at the rim";
  drawing.notes = {lens_note, "Full table (2001 rows): profile.csv; the model: sensor.yaml."};
  WriteProfileDrawing(drawing, (dir / "profile_drawing.svg").string(), (dir / "profile_drawing.png").string());

  // h vs Omega (the seed's Fig. 5) and each curve's departure from the fitted law.
  const ImageCharacteristic law =
      spec.characteristic == ImageCharacteristic::kNone || spec.characteristic == ImageCharacteristic::kSingleViewpoint
          ? ImageCharacteristic::kEquidistant
          : spec.characteristic;
  WriteFileAtomically((dir / "characteristic.csv").string(), [&](std::ostream& out) {
    out << "x_mm,omega_deg,h_px,h_" << CharacteristicName(law) << "_px,viewpoint_z_mm\n" << std::setprecision(12);
    for (const CharacteristicSample& s : achieved.samples)
      out << s.x_mm << ',' << s.omega_deg << ',' << s.h_px << ','
          << achieved.rim_h_px * LawHeightRatio(law, s.omega_deg * M_PI / 180.0, achieved.rim_omega_deg * M_PI / 180.0) << ','
          << s.viewpoint_z_mm << '\n';
  });
  PlotPanel height("Image height h vs Omega (seed Fig. 5)", "Omega (deg)", "h (px)");
  PlotPanel deviation(std::string("Departure from the ") + CharacteristicName(law) + " law", "Omega (deg)", "h - h_law (px)");
  height.series.push_back(Curve("fitted " + std::string(ProfileFamilyName(spec.family)), achieved, 0, false, law));
  deviation.series.push_back(Curve("fitted", achieved, 0, true, law));
  if (compared) {
    height.series.push_back(Curve("compared: " + std::filesystem::path(o.compare_path).filename().string(), *compared, 1, false, law));
    deviation.series.push_back(Curve("compared", *compared, 1, true, law));
  }
  WritePng((dir / "characteristic.png").string(), TilePanels({RenderPanel(height, 700, 450), RenderPanel(deviation, 700, 450)}, 2));

  nlohmann::json j;
  j["profile"] = ProfileFamilyName(spec.family);
  j["characteristic"] = CharacteristicName(spec.characteristic);
  j["targets"] = {{"rim_omega_deg", spec.rim_omega_deg}, {"rim_theta_deg", spec.rim_theta_deg}};
  j["parameters"] = ParametersJson(design, o.rim_radius_mm);
  j["achieved"] = CharacteristicsJson(achieved);
  j["achieved_meaning"] =
      "measured through sensor.yaml's model (Eq. 4-7 per mirror radius, 1000 samples): max |h - h_law| in px with the rim at "
      "rim_h_px, for h_law through the origin and the rim point; viewpoint spread = max - min of Eq. 6's z_v";
  if (compared) {
    j["compared"] = CharacteristicsJson(*compared);
    j["compared"]["file"] = o.compare_path;
  }
  j["solver"] = {{"free_parameters", design.free_params},
                 {"residuals", design.free_params > 0 ? spec.samples : 0},
                 {"iterations", design.iterations},
                 {"final_cost", design.final_cost},
                 {"report", design.solver_report}};
  j["sensor"] = "sensor.yaml";
  WriteFileAtomically((dir / "design.json").string(), [&](std::ostream& out) { out << j.dump(2) << '\n'; });

  if (!context.quiet) {
    std::printf("%s:", ProfileFamilyName(spec.family));
    for (const auto& [name, value] : j["parameters"]["normalised"].items()) std::printf(" %s = %.6g", name.c_str(), value.get<double>());
    std::printf(" (normalised); rim Omega %.4f, Theta %.4f deg", achieved.rim_omega_deg, achieved.rim_theta_deg);
    if (law == spec.characteristic)
      std::printf("; %s law within %.3f px%s", characteristic.c_str(), achieved.LawErrorPx(law),
                  compared ? (" (compared sensor: " + std::to_string(compared->LawErrorPx(law)) + " px)").c_str() : "");
    else if (spec.characteristic == ImageCharacteristic::kSingleViewpoint)
      std::printf("; viewpoint spread %.3g mm", achieved.viewpoint_spread_mm);
    std::printf(" -> %s\n", o.out_dir.c_str());
  }
}

}  // namespace omnical::cli

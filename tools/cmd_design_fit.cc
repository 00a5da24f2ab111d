// omnical design fit: Ohte & Tsuzuki's design by parameters (Table 1) with Ceres: a sphere,
// even polynomial or hyperboloid whose rim ray has the target Omega and Theta, shaped for a
// characteristic; written as a sensor every other subcommand takes, with the image laws the
// design (and optionally another sensor file, for comparison) achieves. The job is
// model/design/design_fit_job.h.
#include "tools/cmd_design_fit.h"

#include <cstdio>
#include <filesystem>

#include "calib/report/design_figures.h"
#include "model/io/atomic_write.h"
#include "model/design/design_files.h"
#include "model/input_error.h"
#include "tools/field_flags.h"
#include "tools/progress.h"
#include "model/io/sensor_yaml.h"
#include "model/model_registry.h"

namespace omnical::cli {

void AddDesignFitOptions(CLI::App* fit, DesignFitFlags* f) {
  DesignFitOptions& o = f->job;
  fit->add_option("--profile", f->profile, "Profile family: " + JoinChoices(DesignProfileNames()))
      ->required()
      ->check(CLI::IsMember(DesignProfileNames()));
  fit->add_option("--terms", o.spec.terms, "How many terms the family's list has: " + DesignTermsHelp())
      ->check(CLI::Range(0, 8))
      ->capture_default_str();
  fit->add_option("--rim-omega", o.spec.rim_omega_deg,
                  "Omega at the rim: the object ray's angle from the -z axis (deg)")
      ->capture_default_str();
  fit->add_option("--rim-theta", o.spec.rim_theta_deg, "Theta at the rim: the lens's viewing angle (deg)")
      ->capture_default_str();
  fit->add_option("--characteristic", f->characteristic,
                  "equidistant, svp, aspect or area (default: svp for a hyperboloid, equidistant for a family with "
                  "freedom left after the rim targets)")
      ->check(CLI::IsMember({"equidistant", "svp", "aspect", "area"}));
  fit->add_option("--rim-radius-mm", o.rim_radius_mm, "Mirror radius M at the rim (mm): scales the normalised design")
      ->check(kPositive)
      ->capture_default_str();
  fit->add_option("--image-size", o.image_size_px, "Square image; the rim images at half its width (the paper's 2N)")
      ->check(CLI::Range(64, 20000))
      ->capture_default_str();
  fit->add_option("--compare", f->compare_path, "Another axial sensor file measured the same way (e.g. Table 1's)");
  fit->add_option("--out", f->out_dir, "Output directory")->required();
}

void RunDesignFit(DesignFitFlags& f, const Context& context) {
  DesignFitOptions& o = f.job;
  o.spec.profile = f.profile;
  o.spec.characteristic = DefaultCharacteristic(o.spec.profile, o.spec.terms);
  for (ImageCharacteristic c : {ImageCharacteristic::kEquidistant, ImageCharacteristic::kSingleViewpoint,
                                ImageCharacteristic::kConstantAspect, ImageCharacteristic::kEqualArea})
    if (f.characteristic == CharacteristicName(c)) o.spec.characteristic = c;
  if (!f.compare_path.empty()) {
    try {
      o.compare = LoadSensorYaml(f.compare_path);
    } catch (const InputError& e) {
      const std::string what = e.what();
      throw InputError(what.rfind(f.compare_path, 0) == 0 ? what : f.compare_path + ": " + what);
    }
    o.compare_source = f.compare_path;
  }
  const FlagTable flags = {{"rim_omega_deg", "--rim-omega"},
                            {"rim_theta_deg", "--rim-theta"},
                            {"terms", "--terms"},
                            {"rim_radius_mm", "--rim-radius-mm"},
                            {"image_size_px", "--image-size"}};
  o.progress = TerminalProgress(context);
  const DesignFitResult r = NamingFlagWords(flags, [&] { return DesignMirrorFit(o); });

  const std::filesystem::path dir(f.out_dir);
  CreateOutputDirectory(dir);
  SaveSensorYaml(r.sensor, (dir / "sensor.yaml").string());
  WriteProfileTable(r.profile, "design fit", (dir / "profile.csv").string());
  WriteFitCharacteristicCsv(r, (dir / "characteristic.csv").string());
  WriteFitDesignFigures(r, dir.string());
  WriteFitDesignJson(r, "sensor.yaml", (dir / "design.json").string());

  if (!context.quiet) {
    std::printf("%s:", r.spec.profile.c_str());
    for (const auto& [name, value] : NormalisedParameters(r.design)) std::printf(" %s = %.6g", name.c_str(), value);
    std::printf(" (normalised); rim Omega %.4f, Theta %.4f deg", r.achieved.rim_omega_deg, r.achieved.rim_theta_deg);
    if (r.law == r.spec.characteristic)
      std::printf(
          "; %s law within %.3f px%s", CharacteristicName(r.law), r.achieved.LawErrorPx(r.law),
          r.compared ? (" (compared sensor: " + std::to_string(r.compared->LawErrorPx(r.law)) + " px)").c_str() : "");
    else if (r.spec.characteristic == ImageCharacteristic::kSingleViewpoint)
      std::printf("; viewpoint spread %.3g mm", r.achieved.viewpoint_spread_mm);
    std::printf(" -> %s\n", f.out_dir.c_str());
  }
}

}  // namespace omnical::cli

// omnical design ode: a mirror profile from Gächter's reflection ODE for an imaging law,
// written as a tabulated sensor every other subcommand takes, with the design's field of
// view, the law checked through omnical's own ray tracing, and the seed's distance
// sensitivity (Figs. 9, 10, 14). The job is model/design/design_ode_job.h.
#include <cstdio>
#include <filesystem>

#include "calib/report/design_figures.h"
#include "model/io/atomic_write.h"
#include "model/design/design_files.h"
#include "model/design/design_ode_job.h"
#include "model/design/design_spec_yaml.h"
#include "model/input_error.h"
#include "tools/cmd_design_fit.h"
#include "tools/commands.h"
#include "tools/progress.h"

namespace omnical::cli {
namespace {

struct OdeFlags {
  std::string spec_path, law, law_table, out_dir;
  DesignOdeOptions job;
};

void RunOde(OdeFlags& flags, const Context& context) {
  DesignOdeOptions& job = flags.job;
  OdeDesignSpec& spec = job.spec;
  if (!flags.spec_path.empty()) {
    spec = LoadOdeDesignSpec(flags.spec_path);
  } else {
    spec.law.kind = flags.law == "linear"     ? ImagingLaw::Kind::kLinear
                    : flags.law == "logpolar" ? ImagingLaw::Kind::kLogPolar
                                              : ImagingLaw::Kind::kTable;
    if (spec.law.kind == ImagingLaw::Kind::kLogPolar) spec.law.rho0_mm = spec.rho0_mm;
    if (spec.law.kind == ImagingLaw::Kind::kTable) {
      if (flags.law_table.empty()) throw InputError("--law table needs --law-table FILE (rows rho_mm, h_mm)");
      LoadLawTable(flags.law_table, &spec.law);
    }
  }
  job.progress = TerminalProgress(context);
  const DesignOdeResult r = DesignMirrorOde(job);
  const std::filesystem::path dir(flags.out_dir);
  CreateOutputDirectory(dir);
  WriteProfileTable(r.profile, "design ode", (dir / job.table_file).string());
  WriteOdeDesignSensorYaml(r, job.table_file, (dir / "sensor.yaml").string());
  WriteLawRatioCsv(r, (dir / "law_ratio.csv").string());
  WriteOdeDesignFigures(r, dir.string());
  WriteOdeDesignJson(r, (dir / "design.json").string());
  if (!context.quiet)
    std::printf(
        "phi0 %.3f deg, phi1 %.3f deg, field of view %.3f deg (ends at %s); law through the traced sensor within "
        "%.2g relative -> %s\n",
        r.design.phi0_deg, r.design.phi1_deg, r.design.phi1_deg - r.design.phi0_deg,
        r.design.ended_at_rim ? "the mirror rim" : "rho1", r.max_law_error_rel, flags.out_dir.c_str());
}

}  // namespace

Command DesignCommand() {
  return {
      "design",
      "Mirror design: the reflection ODE for an imaging law (ode), or a profile family fitted to rim targets (fit)",
      [](CLI::App& sub, const Context& context) -> CommandAction {
        auto flags = std::make_shared<OdeFlags>();
        auto fit_flags = std::make_shared<DesignFitFlags>();
        sub.require_subcommand(1);
        CLI::App* ode =
            sub.add_subcommand("ode", "Gächter's reflection ODE: a profile imaging a cylinder by a law h(rho)");
        OdeDesignSpec& s = flags->job.spec;
        auto* spec = ode->add_option("--spec", flags->spec_path, "Design spec (YAML, see datasets-synthetic/designs)");
        auto* law = ode->add_option("--law", flags->law, "Imaging law: linear, logpolar or table")
                        ->check(CLI::IsMember({"linear", "logpolar", "table"}));
        spec->excludes(law);
        ode->add_option("--focal-length-mm", s.focal_length_mm, "f: the pinhole's focal length (mm)");
        ode->add_option("--distance-mm", s.distance_mm, "d: the reference cylinder's radius (mm)");
        ode->add_option("--start-height-mm", s.start_height_mm, "F0: image plane to mirror vertex (mm)");
        ode->add_option("--rim-limit-mm", s.rim_limit_mm, "t1: the largest mirror radius (mm)");
        ode->add_option("--rho0-mm", s.rho0_mm, "Imager: innermost used radius (mm)");
        ode->add_option("--rho1-mm", s.rho1_mm, "Imager: outermost used radius (mm)");
        ode->add_option("--gain", s.law.gain, "Law gain a (linear: dimensionless; logpolar: mm)");
        ode->add_option("--offset-mm", s.law.offset_mm, "Law offset b (mm)");
        ode->add_option("--growth-rate", s.law.growth_rate, "logpolar: pixel growth rate k (> 1)");
        ode->add_option("--law-table", flags->law_table, "table: CSV rows rho_mm, h_mm (strictly increasing)");
        ode->add_option("--samples", flags->job.samples, "Profile samples written (uniform in x)")
            ->check(CLI::Range(100, 1000000))
            ->capture_default_str();
        ode->add_option("--image-size", flags->job.image_size_px, "Square image of the designed sensor (px)")
            ->check(CLI::Range(64, 20000))
            ->capture_default_str();
        ode->add_option("--out", flags->out_dir, "Output directory")->required();
        ode->callback([spec, law]() {
          if (spec->count() + law->count() == 0) throw CLI::RequiredError("--spec or --law");
        });
        CLI::App* fit = sub.add_subcommand("fit", "Ohte & Tsuzuki's design by parameters (Table 1), solved with Ceres");
        AddDesignFitOptions(fit, fit_flags.get());
        return [flags, fit_flags, fit, &context]() {
          if (fit->parsed())
            RunDesignFit(*fit_flags, context);
          else
            RunOde(*flags, context);
        };
      }};
}

}  // namespace omnical::cli

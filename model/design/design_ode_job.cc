#include "model/design/design_ode_job.h"

#include <algorithm>
#include <cmath>
#include <iterator>

#include "model/input_error.h"

namespace omnical {

std::string DesignOdeOptions::Check() const {
  if (samples < 100 || samples > 1000000) return "samples: must be in [100, 1000000]";
  if (image_size_px < 64 || image_size_px > 20000) return "image_size_px: must be in [64, 20000]";
  if (table_file.empty()) return "table_file: must name the profile table";
  return spec.Check();
}

DesignOdeResult DesignMirrorOde(const DesignOdeOptions& options) {
  if (const std::string why = options.Check(); !why.empty()) throw InputError("design ode: " + why);
  const OdeDesignSpec& spec = options.spec;
  ProgressReporter solving(options.progress, "ode", 1);
  solving.ThrowIfCancelled();
  const OdeDesign design = SolveMirrorOde(spec, options.samples);
  solving.Step();

  const double vertex_mm = design.profile.front().height_mm;
  ProfileTable profile;
  for (const ProfileSample& s : design.profile) {
    profile.radius_mm.push_back(s.radius_mm);
    profile.sag_mm.push_back(s.height_mm - vertex_mm);
    profile.slope.push_back(s.slope);
  }
  const Sensor sensor = SensorFromOdeDesign(spec, design, options.image_size_px, options.table_file);
  const double pitch_mm = PixelPitchMm(design, options.image_size_px);

  // The law through omnical's own ray tracing of the sensor, at d and around it. With
  // rho0 = 0 the centre pixel looks back along the axis at the mirror's tip (the ODE gives
  // it a cusp, slope != 0): the check starts 0.1 % of the field out.
  const double rho_from_mm = spec.rho0_mm > 0.0 ? spec.rho0_mm : 1e-3 * design.rho_end_mm;
  constexpr int kCurves = static_cast<int>(std::size(DesignOdeResult::kLawCheckDistanceFactors));
  ProgressReporter tracing(options.progress, "trace law", kCurves);
  tracing.ThrowIfCancelled();
  std::vector<LawRatioCurve> curves;
  for (double factor : DesignOdeResult::kLawCheckDistanceFactors) {
    curves.push_back(TraceLawRatio(sensor, spec, pitch_mm, factor * spec.distance_mm, rho_from_mm, design.rho_end_mm,
                                   DesignOdeResult::kLawRatioIntervals));
    tracing.Step();
  }
  double worst = 0.0;  // HUGE_VAL where a ray missed
  for (double r : curves[DesignOdeResult::kReferenceCurve].ratio)
    worst = std::isfinite(r) ? std::max(worst, std::abs(r - 1.0)) : HUGE_VAL;
  return {spec,
          design,
          std::move(profile),
          sensor,
          vertex_mm,
          vertex_mm - spec.focal_length_mm,
          pitch_mm,
          std::move(curves),
          worst};
}

}  // namespace omnical

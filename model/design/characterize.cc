#include "model/design/characterize.h"

#include <algorithm>
#include <cmath>
#include <type_traits>

#include "model/input_error.h"
#include "model/object_distance.h"

namespace omnical {
namespace {

constexpr double kDegPerRad = 180.0 / M_PI;

bool Positive(double value) { return std::isfinite(value) && value > 0.0; }

}  // namespace

std::string CharacterizeOptions::Check() const {
  if (lens_focal_mm && !Positive(*lens_focal_mm)) return "lens_focal_mm: must be > 0";
  if (focus_mm)
    if (const std::string why = ObjectDistanceProblem(*focus_mm); !why.empty()) return "focus_mm: " + why;
  if (!Positive(f_number)) return "f_number: must be > 0";
  if (!Positive(pixel_um)) return "pixel_um: must be > 0";
  // In rim radii: 1e8 of them is infinity for any mirror of 1 mm or more.
  if (!(Positive(near_n) && near_n <= kMaxObjectDistanceMm)) return "near_n: must be > 0 and at most 1e8";
  if (samples < 10 || samples > 100000) return "samples: must be in [10, 100000]";
  return {};
}

double CharacterizeResult::rim_omega_deg() const { return field.back().ray.omega_rad * kDegPerRad; }
double CharacterizeResult::rim_theta_deg() const { return field.back().ray.theta_rad * kDegPerRad; }

CharacterizeResult Characterize(const Sensor& sensor, const CharacterizeOptions& options) {
  if (const std::string why = options.Check(); !why.empty()) throw InputError(why);
  if (const std::string why = RimOutsideImage(sensor); !why.empty()) throw InputError("sensor: " + why);
  CharacterizeResult r;
  r.profile_name = sensor.profile_name();
  r.lens_name = sensor.lens_name();
  r.axial = sensor.is_axial();
  r.rim_radius_mm = sensor.rim_radius_mm();
  std::visit([&](const auto& model) { r.m_mm = model.pose.m_mm; }, sensor.model());
  r.samples = options.samples;
  r.pixel_um = options.pixel_um;
  r.near_distance_mm = options.near_n * r.rim_radius_mm;

  r.lens.f_number = options.f_number;
  r.lens.pixel_mm = options.pixel_um * 1e-3;
  // Default focal length: the sensor's own, fx in mm on this pixel pitch.
  std::visit(
      [&](const auto& model) {
        if constexpr (std::decay_t<decltype(model)>::kOrthographic) {
          r.lens.lens_focal_mm = options.lens_focal_mm.value_or(0.0);
        } else {
          r.lens.lens_focal_mm = options.lens_focal_mm.value_or(model.lens.fx_px * r.lens.pixel_mm);
        }
      },
      sensor.model());
  if (!(r.lens.lens_focal_mm > 0.0))
    throw InputError("lens_focal_mm: an orthographic sensor has no focal length of its own; give lens_focal_mm (mm)");

  ProgressReporter analysing(options.progress, "field", 1);
  analysing.ThrowIfCancelled();
  r.field = AnalyzeField(sensor, options.samples, r.near_distance_mm);
  analysing.Step();

  ProgressReporter focusing(options.progress, "focus", 1);
  focusing.ThrowIfCancelled();
  r.focus_searched = !options.focus_mm.has_value();
  if (options.focus_mm) {
    r.focus_mm = *options.focus_mm;
    r.mean_blur_area_deg2 = MeanBlurAreaDeg2(r.field, r.lens, r.focus_mm);
  } else {
    r.focus_mm = BestFocusDistanceMm(r.field, r.lens, &r.mean_blur_area_deg2);
  }
  r.depth_of_field_mm = DepthOfFieldMm(r.lens, r.focus_mm);
  focusing.Step();

  double caustic_x = 0.0, caustic_z_lo = HUGE_VAL, caustic_z_hi = -HUGE_VAL;
  r.viewpoint_min_mm = HUGE_VAL, r.viewpoint_max_mm = -HUGE_VAL, r.dh_domega_min = HUGE_VAL;
  for (const FieldSample& f : r.field) {
    caustic_x = std::max(caustic_x, std::abs(f.caustic_x_mm));
    caustic_z_lo = std::min(caustic_z_lo, f.caustic_z_mm), caustic_z_hi = std::max(caustic_z_hi, f.caustic_z_mm);
    r.viewpoint_min_mm = std::min(r.viewpoint_min_mm, f.ray.viewpoint_z_mm);
    r.viewpoint_max_mm = std::max(r.viewpoint_max_mm, f.ray.viewpoint_z_mm);
    r.max_astigmatism_mm =
        std::max(r.max_astigmatism_mm, std::abs(f.tangential_far.lens_distance_mm - f.sagittal_far.lens_distance_mm));
    r.blur.push_back(BlurAt(f, r.lens, r.focus_mm));
    r.worst_blur_px =
        std::max({r.worst_blur_px, std::abs(r.blur.back().tangential_px), std::abs(r.blur.back().sagittal_px)});
    r.dh_domega_min = std::min(r.dh_domega_min, f.delta_h_px),
    r.dh_domega_max = std::max(r.dh_domega_max, f.delta_h_px);
  }
  r.caustic_radial_mm = caustic_x;
  r.caustic_axial_mm = caustic_z_hi - caustic_z_lo;
  r.mean_solid_angle_per_pixel_deg2 = MeanSolidAnglePerPixelDeg2(r.field);

  if (!r.axial) {
    ProgressReporter tracing(options.progress, "azimuth curves", 4);
    tracing.ThrowIfCancelled();
    for (int k = 0; k < 4; ++k) {
      r.azimuth_curves.push_back(ExactAzimuthCurve(sensor, k * M_PI / 2.0, options.samples));
      tracing.Step();
    }
  }
  return r;
}

}  // namespace omnical

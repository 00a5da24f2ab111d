#include "model/design/design_fit_job.h"

#include <cmath>

#include "model/input_error.h"
#include "model/ray_quantities.h"
#include "model/sensor.h"

namespace omnical {

std::string DesignFitOptions::Check() const {
  if (const std::string why = spec.Check(); !why.empty()) return why;
  // The sensor reader's bounds (a 1e-300 mm rim was written and then refused on reading).
  if (!(rim_radius_mm >= kMinRimRadiusMm && rim_radius_mm <= kMaxRimRadiusMm)) return "rim_radius_mm: must be 1e-3 to 1e5 mm";
  if (image_size_px < 64 || image_size_px > 20000) return "image_size_px: must be in [64, 20000]";
  // Upper bounds: 1e9 samples ran for minutes or ran out of memory.
  if (characteristic_samples < 2 || characteristic_samples > 100000) return "characteristic_samples: must be 2 to 100000";
  if (profile_samples < 4 || profile_samples > 100000) return "profile_samples: must be 4 to 100000";
  return {};
}

ImageCharacteristic DefaultCharacteristic(const std::string& profile, int terms) {
  FitDesignSpec spec;
  spec.profile = profile;
  spec.terms = terms;
  spec.characteristic = ImageCharacteristic::kEquidistant;
  // A hyperboloid is shaped for its single viewpoint; any other family with freedom left
  // after the rim targets (the spec then checks) for the equidistant law.
  if (profile == "hyperboloid") return ImageCharacteristic::kSingleViewpoint;
  return spec.Check().empty() ? ImageCharacteristic::kEquidistant : ImageCharacteristic::kNone;
}

std::vector<std::pair<std::string, double>> NormalisedParameters(const FitDesign& design) {
  std::vector<std::pair<std::string, double>> parameters;
  for (size_t k = 0; k < design.params.size(); ++k) parameters.emplace_back(design.names[k], design.params[k]);
  parameters.emplace_back("m", design.m);
  return parameters;
}

DesignFitResult DesignMirrorFit(const DesignFitOptions& options) {
  if (const std::string why = options.Check(); !why.empty()) throw InputError("design fit: " + why);
  // The compared sensor first, so a bad one costs no fitting.
  std::optional<CharacteristicReport> compared;
  if (options.compare) {
    ProgressReporter measuring(options.progress, "measure compared", 1);
    measuring.ThrowIfCancelled();
    try {
      compared = MeasureCharacteristics(*options.compare, options.characteristic_samples);
    } catch (const InputError& e) {
      const std::string what = e.what();
      const std::string& source = options.compare_source.empty() ? "compare" : options.compare_source;
      throw InputError(what.rfind(source, 0) == 0 ? what : source + ": " + what);
    }
    measuring.Step();
  }

  const FitDesign design = FitMirrorDesign(options.spec, options.progress);
  ProgressReporter measuring(options.progress, "measure", 1);
  measuring.ThrowIfCancelled();
  const Sensor sensor = SensorFromFitDesign(design, options.spec, options.rim_radius_mm, options.image_size_px);
  CharacteristicReport achieved = MeasureCharacteristics(sensor, options.characteristic_samples);

  // The profile in mm through the sensor's own model.
  ProfileTable profile;
  std::visit(
      [&](const auto& model) {
        for (int i = 0; i <= options.profile_samples; ++i) {
          const AxialRayQuantities q = ComputeAxialRay(model, options.rim_radius_mm * i / options.profile_samples);
          profile.radius_mm.push_back(q.x_mm);
          profile.sag_mm.push_back(q.z_mm);
          profile.slope.push_back(std::tan(q.beta_rad));
        }
      },
      sensor.model());
  measuring.Step();

  const ImageCharacteristic c = options.spec.characteristic;
  const ImageCharacteristic law = c == ImageCharacteristic::kNone || c == ImageCharacteristic::kSingleViewpoint
                                      ? ImageCharacteristic::kEquidistant
                                      : c;
  return {options.spec,
          design,
          options.rim_radius_mm,
          sensor,
          std::move(profile),
          std::move(achieved),
          std::move(compared),
          options.compare ? options.compare_source : std::string(),
          law};
}

}  // namespace omnical

#include "model/design/mirror_design_fit.h"
#include "model/ceres_progress.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

#include "model/input_error.h"
#include "model/model_registry.h"
#include "model/ray_quantities.h"

namespace omnical {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

struct RimTargets {
  double tan_beta, tan_theta, omega_rad;
  explicit RimTargets(const FitDesignSpec& spec)
      : tan_beta(std::tan(0.5 * (spec.rim_omega_deg - spec.rim_theta_deg) * kDegToRad)),
        tan_theta(std::tan(spec.rim_theta_deg * kDegToRad)),
        omega_rad(spec.rim_omega_deg * kDegToRad) {}
};

// The profile family as a prototype: its parameter count (the terms) with zero values.
template <typename Profile>
Profile Prototype(int terms) {
  int count = 0;
  for (const ParameterField& field : Profile::kFields) count += field.is_list() ? terms : 1;
  const std::vector<double> zeros(std::max(count, 1), 0.0);
  return Profile::FromParams(zeros.data(), count);
}

// Sag z and slope dz/dx at radius x (normalised) of the family with these parameters,
// through the same profile types the sensor model projects with.
template <typename Profile, typename T>
void SagAndSlope(const Profile& family, const std::vector<T>& params, const T& x, T* z, T* slope) {
  const SagDerivatives<T> g = family.template WithParams<T>(params.data()).template EvaluateSag<T>(x * x);
  T curvature;
  RadialSlopes(g, x, slope, &curvature);
  *z = g.z;
}

// The family's parameters with the two rim targets solved exactly from the free ones
// (every parameter but kRimSlopeParam, in order).
template <typename Profile, typename T>
std::vector<T> ConstrainedParams(const Profile& family, const RimTargets& rim, const T* free, T* m) {
  const int count = family.NumParams();
  std::vector<T> params(count, T(0.0));
  for (int k = 0, next = 0; k < count; ++k)
    if (k != Profile::kRimSlopeParam) params[k] = free[next++];
  Profile::SolveRimSlope(params.data(), count, T(rim.tan_beta));
  T z_rim, slope_rim;
  SagAndSlope(family, params, T(1.0), &z_rim, &slope_rim);
  *m = T(1.0 / rim.tan_theta) - z_rim;
  return params;
}

template <typename T>
T LawRatio(ImageCharacteristic characteristic, const T& omega, double rim_omega) {
  using std::sin;
  using std::tan;
  switch (characteristic) {
    case ImageCharacteristic::kEquidistant: return omega / T(rim_omega);
    case ImageCharacteristic::kConstantAspect: return tan(T(0.5) * omega) / T(std::tan(0.5 * rim_omega));
    case ImageCharacteristic::kEqualArea: return sin(T(0.5) * omega) / T(std::sin(0.5 * rim_omega));
    default: return T(NAN);
  }
}

// One residual per sample x_i = i / samples: the image height's departure from the law
// (in rim heights), or for a single viewpoint the viewpoint's from the rim ray's (in
// mirror radii).
template <typename Profile>
struct CharacteristicResiduals {
  FitDesignSpec spec;
  RimTargets rim;
  Profile family;

  template <typename T>
  bool operator()(T const* const* free, T* residuals) const {
    using std::atan;
    using std::atan2;
    using std::cos;
    using std::sin;
    T m;
    const std::vector<T> params = ConstrainedParams(family, rim, free[0], &m);
    T z_rim, slope_rim;
    SagAndSlope(family, params, T(1.0), &z_rim, &slope_rim);
    const T viewpoint_rim = z_rim + T(1.0 / std::tan(rim.omega_rad));
    for (int i = 1; i <= spec.samples; ++i) {
      const T x(static_cast<double>(i) / spec.samples);
      T z, slope;
      SagAndSlope(family, params, x, &z, &slope);
      const T omega = T(2.0) * atan(slope) + atan2(x, m + z);
      if (spec.characteristic == ImageCharacteristic::kSingleViewpoint) {
        residuals[i - 1] = z + x * cos(omega) / sin(omega) - viewpoint_rim;
      } else {
        residuals[i - 1] = x / (m + z) / T(rim.tan_theta) - LawRatio(spec.characteristic, omega, rim.omega_rad);
      }
    }
    return true;
  }
};

// The image must be one-to-one: Omega and the image height grow with x, the lens below
// the mirror.
template <typename Profile>
void CheckPhysical(const Profile& family, const FitDesign& design) {
  const char* name = Profile::kName;
  if (!(design.m > 0.0))
    throw InputError(std::string("design fit: the fitted ") + name + " puts the lens at m = " + std::to_string(design.m) +
                     " (must be > 0: the rim targets ask for a lens inside the mirror)");
  constexpr int kChecks = 4000;
  double previous_omega = 0.0, previous_h = 0.0;
  for (int i = 1; i <= kChecks; ++i) {
    const double x = static_cast<double>(i) / kChecks;
    double z, slope;
    SagAndSlope(family, design.params, x, &z, &slope);
    const double h = x / (design.m + z);
    const double omega = 2.0 * std::atan(slope) + std::atan2(x, design.m + z);
    if (!(design.m + z > 0.0) || !(h > previous_h) || !(omega > previous_omega) || !std::isfinite(omega)) {
      char why[200];
      std::snprintf(why, sizeof why, "design fit: the fitted %s folds the image: %s stops increasing at x = %.4f (mirror radii)",
                    name, !(omega > previous_omega) ? "Omega" : "the image height", x);
      throw InputError(why);
    }
    previous_omega = omega;
    previous_h = h;
  }
}

template <typename Profile>
FitDesign FitFamily(const FitDesignSpec& spec, const ProgressCallback& progress) {
  const RimTargets rim(spec);
  const Profile family = Prototype<Profile>(spec.terms);
  FitDesign design;
  design.profile = Profile::kName;
  design.free_params = family.NumParams() - 1;
  // Starting points: the family's member nearest a sphere of one mirror radius
  // (FromVertexRadius), further terms at 0: the polynomial starts from the parabola through
  // the rim slope, the hyperboloid from A = 1.
  const Profile near_sphere = Profile::FromVertexRadius(1.0, 1.0);
  std::vector<double> start(std::max(near_sphere.NumParams(), family.NumParams()), 0.0);
  near_sphere.ToParams(start.data());
  std::vector<double> free;
  std::vector<bool> positive;
  ForEachProfileParameter<Profile>(family.NumParams(), [&](const ParameterField& field, int, int index) {
    if (index == Profile::kRimSlopeParam) return;
    positive.push_back(field.domain == FieldDomain::kPositive);
    const bool beyond_start = index >= near_sphere.NumParams() || index >= static_cast<int>(start.size());
    free.push_back(beyond_start ? 0.0 : start[index]);
  });
  if (design.free_params > 0) {
    auto* cost = new ceres::DynamicAutoDiffCostFunction<CharacteristicResiduals<Profile>, 4>(
        new CharacteristicResiduals<Profile>{spec, rim, family});
    cost->AddParameterBlock(design.free_params);
    cost->SetNumResiduals(spec.samples);
    ceres::Problem problem;
    problem.AddResidualBlock(cost, nullptr, free.data());
    for (int k = 0; k < design.free_params; ++k)
      if (positive[k]) problem.SetParameterLowerBound(free.data(), k, 1e-6);
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::DENSE_QR;
    options.max_num_iterations = 500;
    options.function_tolerance = 1e-16;
    options.gradient_tolerance = 1e-16;
    options.parameter_tolerance = 1e-14;
    options.logging_type = ceres::SILENT;  // a library never prints (a step off the domain is routine)
    ProgressReporter reporter(progress, "fit", options.max_num_iterations);
    reporter.ThrowIfCancelled();
    IterationProgress iteration_progress(&reporter);
    options.callbacks.push_back(&iteration_progress);
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
    reporter.ThrowIfCancelled();
    design.iterations = static_cast<int>(summary.iterations.size()) - 1;
    design.final_cost = summary.final_cost;
    design.solver_report = summary.BriefReport();
    if (summary.termination_type != ceres::CONVERGENCE)
      throw InputError("design fit: Ceres did not converge for the " + design.profile + " (" + summary.message + ")");
  } else {
    design.solver_report = "closed form (no free parameter after the rim targets)";
  }
  design.params = ConstrainedParams(family, rim, free.data(), &design.m);
  ForEachProfileParameter<Profile>(family.NumParams(), [&](const ParameterField& field, int k, int) {
    const int power = field.TermLengthPower(k);
    design.names.push_back(field.is_list() ? field.TermName(k) : field.key);
    design.mm_names.push_back(field.is_list() ? field.TermName(k) + "_per_mm" + (power == -1 ? "" : std::to_string(-power))
                                              : field.name);
    design.length_powers.push_back(power);
  });
  CheckPhysical(family, design);
  return design;
}

// Calls f(TypeTag<Catadioptric<double, Profile, PinholeLens>>) for the design profile of
// that name; false if there is none.
template <typename F>
bool WithDesignProfile(const std::string& name, const F& f) {
  bool found = false;
  ForEachModelType([&](auto tag) {
    using Model = typename decltype(tag)::type;
    using Profile = typename Model::ProfileType;
    if constexpr (Profile::kRimSlopeParam >= 0 && !Model::kOrthographic) {
      if (found || name != Profile::kName) return;
      found = true;
      f(tag);
    }
  });
  return found;
}

// The number of free parameters after the rim targets, -1 for an unknown profile.
int FreeParams(const FitDesignSpec& spec) {
  int free = -1;
  WithDesignProfile(spec.profile, [&](auto tag) {
    using Profile = typename decltype(tag)::type::ProfileType;
    free = Prototype<Profile>(spec.terms).NumParams() - 1;
  });
  return free;
}

}  // namespace

const char* CharacteristicName(ImageCharacteristic characteristic) {
  switch (characteristic) {
    case ImageCharacteristic::kNone: return "none";
    case ImageCharacteristic::kEquidistant: return "equidistant";
    case ImageCharacteristic::kSingleViewpoint: return "svp";
    case ImageCharacteristic::kConstantAspect: return "aspect";
    case ImageCharacteristic::kEqualArea: return "area";
  }
  return "?";
}

std::string FitDesignSpec::Check() const {
  if (!std::isfinite(rim_theta_deg) || !(rim_theta_deg > 0.0 && rim_theta_deg < 90.0))
    return "rim_theta_deg: must be in (0, 90) deg (the lens's half field at the rim)";
  if (!std::isfinite(rim_omega_deg) || !(rim_omega_deg > rim_theta_deg && rim_omega_deg < 180.0))
    return "rim_omega_deg: must lie between rim_theta_deg and 180 deg (Omega = 2 beta + Theta with a slope 0 < beta < 90 deg)";
  std::string terms_problem;
  const bool known = WithDesignProfile(profile, [&](auto tag) {
    using Profile = typename decltype(tag)::type::ProfileType;
    const ParameterField& last = Profile::kFields.back();
    if (last.is_list() && (terms < last.min_count || terms > last.max_count))
      terms_problem = "terms: must be " + std::to_string(last.min_count) + " to " + std::to_string(last.max_count) +
                      " for a " + profile;
  });
  if (!known) return "profile: must be " + JoinChoices(DesignProfileNames()) + ", not '" + profile + "'";
  if (!terms_problem.empty()) return terms_problem;
  if (samples < 10 || samples > 100000) return "samples: must be in [10, 100000]";
  const int free = FreeParams(*this);
  if (free == 0 && characteristic != ImageCharacteristic::kNone)
    return "characteristic: a " + profile + (profile == "polynomial" ? " of one term" : "") +
           " is fixed by the two rim targets; nothing is left to shape for a characteristic (its laws are reported in "
           "design.json anyway)";
  if (free > 0 && characteristic == ImageCharacteristic::kNone)
    return "characteristic: a " + profile + " keeps " + std::to_string(free) +
           " free parameter(s) after the rim targets; name the characteristic that fixes them";
  return {};
}

FitDesign FitMirrorDesign(const FitDesignSpec& spec, const ProgressCallback& progress) {
  if (const std::string why = spec.Check(); !why.empty()) throw InputError("design fit: " + why);
  FitDesign design;
  WithDesignProfile(spec.profile, [&](auto tag) {
    design = FitFamily<typename decltype(tag)::type::ProfileType>(spec, progress);
  });
  return design;
}

Sensor SensorFromFitDesign(const FitDesign& design, const FitDesignSpec& spec, double rim_radius_mm, int image_size_px) {
  const double scale = rim_radius_mm;
  const double focal_px = 0.5 * image_size_px / std::tan(spec.rim_theta_deg * kDegToRad);
  const double centre_px = 0.5 * (image_size_px - 1);
  std::optional<Sensor> sensor;
  WithDesignProfile(design.profile, [&](auto tag) {
    typename decltype(tag)::type model;
    model.lens = PinholeLens<double>{focal_px, focal_px, centre_px, centre_px, 0.0, 0.0, 0.0, 0.0};
    model.pose = MirrorPose<double>{design.m * scale, 0.0, 0.0, 0.0, 0.0};
    // A parameter of length power p (z = sum c_k x^2k: c_k in mm^(1-2k)) scales by M^p.
    std::vector<double> mm(design.params.size());
    for (size_t k = 0; k < mm.size(); ++k) mm[k] = design.params[k] * std::pow(scale, design.length_powers[k]);
    model.mirror = Prototype<typename decltype(tag)::type::ProfileType>(spec.terms).WithParams(mm.data());
    model.rim_radius_mm = rim_radius_mm;
    model.image_width_px = model.image_height_px = image_size_px;
    sensor = Sensor(model);
  });
  if (!sensor) throw InputError("design fit: unknown profile family '" + design.profile + "'");
  return *sensor;
}

double LawHeightRatio(ImageCharacteristic characteristic, double omega_rad, double rim_omega_rad) {
  return LawRatio(characteristic, omega_rad, rim_omega_rad);
}

double CharacteristicReport::LawErrorPx(ImageCharacteristic characteristic) const {
  switch (characteristic) {
    case ImageCharacteristic::kEquidistant: return equidistant_max_px;
    case ImageCharacteristic::kConstantAspect: return constant_aspect_max_px;
    case ImageCharacteristic::kEqualArea: return equal_area_max_px;
    default: return NAN;
  }
}

CharacteristicReport MeasureCharacteristics(const Sensor& sensor, int samples) {
  if (!sensor.is_axial())
    throw InputError("characteristics: the sensor's mirror is tilted or decentred; the image laws are defined for an axial sensor");
  CharacteristicReport report;
  std::visit(
      [&](const auto& model) {
        const double cx = model.lens.cx_px;
        for (int i = 0; i <= samples; ++i) {
          const double x = model.rim_radius_mm * i / samples;
          const AxialRayQuantities q = ComputeAxialRay(model, x);
          Vec2<double> pixel;
          if (!model.lens.ProjectToPixel(Vec3<double>(x, 0.0, model.pose.m_mm + q.z_mm), &pixel))
            throw InputError("characteristics: the lens cannot image the mirror point at x = " + std::to_string(x) + " mm");
          report.samples.push_back({x, q.omega_rad / kDegToRad, pixel.x() - cx, q.viewpoint_z_mm});
          if (i == samples) report.rim_theta_deg = q.theta_rad / kDegToRad;
        }
      },
      sensor.model());
  const CharacteristicSample& rim = report.samples.back();
  report.rim_h_px = rim.h_px;
  report.rim_omega_deg = rim.omega_deg;
  double low = HUGE_VAL, high = -HUGE_VAL;
  for (const CharacteristicSample& s : report.samples) {
    const double omega = s.omega_deg * kDegToRad, rim_omega = rim.omega_deg * kDegToRad;
    auto error = [&](ImageCharacteristic c) { return std::abs(s.h_px - rim.h_px * LawRatio(c, omega, rim_omega)); };
    report.equidistant_max_px = std::max(report.equidistant_max_px, error(ImageCharacteristic::kEquidistant));
    report.constant_aspect_max_px = std::max(report.constant_aspect_max_px, error(ImageCharacteristic::kConstantAspect));
    report.equal_area_max_px = std::max(report.equal_area_max_px, error(ImageCharacteristic::kEqualArea));
    low = std::min(low, s.viewpoint_z_mm);
    high = std::max(high, s.viewpoint_z_mm);
  }
  report.viewpoint_spread_mm = high - low;
  return report;
}

}  // namespace omnical

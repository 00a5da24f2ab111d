#include "model/design/mirror_design_fit.h"
#include "model/ceres_progress.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "model/input_error.h"
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

int FreeParams(const FitDesignSpec& spec) {
  switch (spec.family) {
    case ProfileFamily::kSphere: return 0;
    case ProfileFamily::kHyperboloid: return 1;
    case ProfileFamily::kPolynomial: return spec.polynomial_terms - 1;
  }
  return 0;
}

// Sag z and slope dz/dx at radius x (normalised) of the family with these parameters,
// through the same profile types the sensor model projects with.
template <typename T>
void SagAndSlope(ProfileFamily family, const std::vector<T>& params, const T& x, T* z, T* slope) {
  const T r2 = x * x;
  SagDerivatives<T> g{T(0.0), T(0.0), T(0.0)};
  switch (family) {
    case ProfileFamily::kSphere: g = SphereProfile<T>{params[0]}.template EvaluateSag<T>(r2); break;
    case ProfileFamily::kHyperboloid: g = HyperboloidProfile<T>{params[0], params[1]}.template EvaluateSag<T>(r2); break;
    case ProfileFamily::kPolynomial:
      g = EvenPolynomialProfile<T>::FromParams(params.data(), static_cast<int>(params.size())).template EvaluateSag<T>(r2);
      break;
  }
  T curvature;
  RadialSlopes(g, x, slope, &curvature);
  *z = g.z;
}

// The family's parameters with the two rim targets solved exactly from the free ones.
template <typename T>
std::vector<T> ConstrainedParams(const FitDesignSpec& spec, const RimTargets& rim, const T* free, T* m) {
  using std::sqrt;
  std::vector<T> params;
  switch (spec.family) {
    case ProfileFamily::kSphere:
      // f'(1) = 1 / sqrt(A^2 - 1) = tan(beta).
      params = {T(std::sqrt(1.0 + 1.0 / (rim.tan_beta * rim.tan_beta)))};
      break;
    case ProfileFamily::kHyperboloid:
      // f'(1) = (B / A) / sqrt(A^2 + 1) = tan(beta).
      params = {free[0], free[0] * sqrt(free[0] * free[0] + T(1.0)) * T(rim.tan_beta)};
      break;
    case ProfileFamily::kPolynomial: {
      // f'(1) = sum 2k c_k = tan(beta), solved for c1.
      params.assign(spec.polynomial_terms, T(0.0));
      T rest(0.0);
      for (int k = 1; k < spec.polynomial_terms; ++k) {
        params[k] = free[k - 1];
        rest += T(2.0 * (k + 1)) * params[k];
      }
      params[0] = T(0.5) * (T(rim.tan_beta) - rest);
      break;
    }
  }
  T z_rim, slope_rim;
  SagAndSlope(spec.family, params, T(1.0), &z_rim, &slope_rim);
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
struct CharacteristicResiduals {
  FitDesignSpec spec;
  RimTargets rim;

  template <typename T>
  bool operator()(T const* const* free, T* residuals) const {
    using std::atan;
    using std::atan2;
    using std::cos;
    using std::sin;
    T m;
    const std::vector<T> params = ConstrainedParams(spec, rim, free[0], &m);
    T z_rim, slope_rim;
    SagAndSlope(spec.family, params, T(1.0), &z_rim, &slope_rim);
    const T viewpoint_rim = z_rim + T(1.0 / std::tan(rim.omega_rad));
    for (int i = 1; i <= spec.samples; ++i) {
      const T x(static_cast<double>(i) / spec.samples);
      T z, slope;
      SagAndSlope(spec.family, params, x, &z, &slope);
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
void CheckPhysical(const FitDesignSpec& spec, const FitDesign& design) {
  const char* family = ProfileFamilyName(spec.family);
  if (!(design.m > 0.0))
    throw InputError(std::string("design fit: the fitted ") + family + " puts the lens at m = " + std::to_string(design.m) +
                     " (must be > 0: the rim targets ask for a lens inside the mirror)");
  constexpr int kChecks = 4000;
  double previous_omega = 0.0, previous_h = 0.0;
  for (int i = 1; i <= kChecks; ++i) {
    const double x = static_cast<double>(i) / kChecks;
    double z, slope;
    SagAndSlope(spec.family, design.params, x, &z, &slope);
    const double h = x / (design.m + z);
    const double omega = 2.0 * std::atan(slope) + std::atan2(x, design.m + z);
    if (!(design.m + z > 0.0) || !(h > previous_h) || !(omega > previous_omega)) {
      char why[200];
      std::snprintf(why, sizeof why, "design fit: the fitted %s folds the image: %s stops increasing at x = %.4f (mirror radii)",
                    family, !(omega > previous_omega) ? "Omega" : "the image height", x);
      throw InputError(why);
    }
    previous_omega = omega;
    previous_h = h;
  }
}

}  // namespace

const char* ProfileFamilyName(ProfileFamily family) {
  switch (family) {
    case ProfileFamily::kSphere: return "sphere";
    case ProfileFamily::kPolynomial: return "polynomial";
    case ProfileFamily::kHyperboloid: return "hyperboloid";
  }
  return "?";
}

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
  if (family == ProfileFamily::kPolynomial && (polynomial_terms < 1 || polynomial_terms > 8))
    return "polynomial_terms: a polynomial has 1 to 8 even terms";
  if (samples < 10 || samples > 100000) return "samples: must be in [10, 100000]";
  const int free = FreeParams(*this);
  if (free == 0 && characteristic != ImageCharacteristic::kNone)
    return std::string("characteristic: a ") + ProfileFamilyName(family) +
           (family == ProfileFamily::kPolynomial ? " of one term" : "") +
           " is fixed by the two rim targets; nothing is left to shape for a characteristic (its laws are reported in "
           "design.json anyway)";
  if (free > 0 && characteristic == ImageCharacteristic::kNone)
    return std::string("characteristic: a ") + ProfileFamilyName(family) + " keeps " + std::to_string(free) +
           " free parameter(s) after the rim targets; name the characteristic that fixes them";
  return {};
}

FitDesign FitMirrorDesign(const FitDesignSpec& spec, const ProgressCallback& progress) {
  if (const std::string why = spec.Check(); !why.empty()) throw InputError("design fit: " + why);
  const RimTargets rim(spec);
  FitDesign design;
  design.family = spec.family;
  design.free_params = FreeParams(spec);
  std::vector<double> free(design.free_params, 0.0);
  // Starting points: the polynomial from the parabola through the rim slope (c2.. = 0),
  // the hyperboloid from A = 1 (one mirror radius).
  if (spec.family == ProfileFamily::kHyperboloid) free[0] = 1.0;
  if (design.free_params > 0) {
    auto* cost = new ceres::DynamicAutoDiffCostFunction<CharacteristicResiduals, 4>(new CharacteristicResiduals{spec, rim});
    cost->AddParameterBlock(design.free_params);
    cost->SetNumResiduals(spec.samples);
    ceres::Problem problem;
    problem.AddResidualBlock(cost, nullptr, free.data());
    if (spec.family == ProfileFamily::kHyperboloid) problem.SetParameterLowerBound(free.data(), 0, 1e-6);
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::DENSE_QR;
    options.max_num_iterations = 500;
    options.function_tolerance = 1e-16;
    options.gradient_tolerance = 1e-16;
    options.parameter_tolerance = 1e-14;
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
      throw InputError("design fit: Ceres did not converge for the " + std::string(ProfileFamilyName(spec.family)) + " (" +
                       summary.message + ")");
  } else {
    design.solver_report = "closed form (no free parameter after the rim targets)";
  }
  design.params = ConstrainedParams(spec, rim, free.data(), &design.m);
  CheckPhysical(spec, design);
  return design;
}

Sensor SensorFromFitDesign(const FitDesign& design, const FitDesignSpec& spec, double rim_radius_mm, int image_size_px) {
  const double scale = rim_radius_mm;
  const double focal_px = 0.5 * image_size_px / std::tan(spec.rim_theta_deg * kDegToRad);
  const double centre_px = 0.5 * (image_size_px - 1);
  const PinholeLens<double> lens{focal_px, focal_px, centre_px, centre_px, 0.0, 0.0};
  const MirrorPose<double> pose{design.m * scale, 0.0, 0.0, 0.0, 0.0};
  auto finish = [&](auto model) {
    model.lens = lens;
    model.pose = pose;
    model.rim_radius_mm = rim_radius_mm;
    model.image_width_px = model.image_height_px = image_size_px;
    return Sensor(model);
  };
  switch (design.family) {
    case ProfileFamily::kSphere: {
      Catadioptric<double, SphereProfile, PinholeLens> model;
      model.mirror = {design.params[0] * scale};
      return finish(model);
    }
    case ProfileFamily::kHyperboloid: {
      Catadioptric<double, HyperboloidProfile, PinholeLens> model;
      model.mirror = {design.params[0] * scale, design.params[1] * scale};
      return finish(model);
    }
    case ProfileFamily::kPolynomial: {
      // z = sum c_k x^2k with x in mirror radii: c_k (mm^(1-2k)) = c_k / M^(2k-1).
      Catadioptric<double, EvenPolynomialProfile, PinholeLens> model;
      model.mirror.num_coefficients = static_cast<int>(design.params.size());
      for (size_t k = 0; k < design.params.size(); ++k)
        model.mirror.coefficients[k] = design.params[k] / std::pow(scale, 2.0 * (k + 1) - 1.0);
      return finish(model);
    }
  }
  throw InputError("design fit: unknown profile family");
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

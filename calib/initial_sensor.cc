#include "calib/initial_sensor.h"

#include <ceres/ceres.h>

#include <cmath>
#include <variant>

#include "model/input_error.h"

namespace omnical {

namespace {

// A mirror of family P from its parameters (the polynomial needs its count).
template <template <typename> class P>
struct Make {
  template <typename T>
  static P<T> From(const T* params, int /*count*/) { return P<T>::FromParams(params); }
};
template <>
struct Make<EvenPolynomialProfile> {
  template <typename T>
  static EvenPolynomialProfile<T> From(const T* params, int count) {
    return EvenPolynomialProfile<T>::FromParams(params, count);
  }
};

// Sag (mm) and slope x rim radius (mm) of P against the sampled target.
template <template <typename> class P>
struct SagResidual {
  double r2, z_mm, slope_times_rim_mm, rim_mm;
  int count;
  template <typename T>
  bool operator()(const T* params, T* residual) const {
    const SagDerivatives<T> g = Make<P>::template From<T>(params, count).EvaluateSag(T(r2));
    residual[0] = g.z - T(z_mm);
    residual[1] = (T(2.0 * std::sqrt(r2)) * g.dz_ds) * T(rim_mm) - T(slope_times_rim_mm);
    return true;
  }
};

template <template <typename> class P, int N>
std::vector<double> FitProfile(const std::vector<SagDerivatives<double>>& samples, const std::vector<double>& r2s,
                               double rim_mm, std::vector<double> start, int count) {
  ceres::Problem problem;
  for (size_t i = 0; i < samples.size(); ++i) {
    auto* cost = new ceres::AutoDiffCostFunction<SagResidual<P>, 2, N>(new SagResidual<P>{
        r2s[i], samples[i].z, 2.0 * std::sqrt(r2s[i]) * samples[i].dz_ds * rim_mm, rim_mm, count});
    problem.AddResidualBlock(cost, nullptr, start.data());
  }
  ceres::Solver::Options options;
  options.max_num_iterations = 200;
  options.function_tolerance = 1e-14;
  options.parameter_tolerance = 1e-14;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  return start;
}

// The guess's model with another mirror.
template <template <typename> class P, typename Model>
SensorModel WithMirror(const Model& model, const P<double>& mirror) {
  auto copy = [&](auto out) -> SensorModel {
    out.mirror = mirror;
    out.lens = model.lens;
    out.pose = model.pose;
    out.rim_radius_mm = model.rim_radius_mm;
    out.image_width_px = model.image_width_px;
    out.image_height_px = model.image_height_px;
    out.camera_body_radius_mm = model.camera_body_radius_mm;
    return out;
  };
  if constexpr (Model::kOrthographic)
    return copy(Catadioptric<double, P, OrthographicLens>{});
  else
    return copy(Catadioptric<double, P, PinholeLens>{});
}

Sensor Validated(SensorModel model, const std::string& what) {
  const std::string problem = ValidateSensorModel(model);
  if (!problem.empty()) throw InputError(InputMessage(what, "profile", "the starting sensor is not valid: " + problem));
  return Sensor(std::move(model));
}

}  // namespace

Sensor SensorFromRimCircle(const RimCircle& rim, int image_width_px, int image_height_px, const std::string& profile,
                           double rim_field_deg) {
  if (!(rim.radius_px > 0.0) || !rim.centre_px.allFinite())
    throw InputError(InputMessage("rim circle", "", "no mirror rim found in the images"));
  if (!(rim_field_deg > 10.0 && rim_field_deg < 170.0))
    throw InputError(InputMessage("rim_field_deg", "", "must lie in (10, 170) deg"));
  const double rim_mm = kNominalRimRadiusMm;
  const double slope = std::tan(0.5 * rim_field_deg * M_PI / 180.0);  // dz/dr at the rim
  Catadioptric<double, ParaboloidProfile, OrthographicLens> base;
  base.lens = {rim.radius_px / rim_mm, rim.centre_px.x(), rim.centre_px.y()};
  base.pose = {100.0, 0.0, 0.0, 0.0, 0.0};  // m: any value in front of the lens (unobservable here)
  base.rim_radius_mm = rim_mm;
  base.image_width_px = image_width_px;
  base.image_height_px = image_height_px;
  // Paraboloid z = r^2 / (4 A): slope r / (2 A).
  base.mirror = {rim_mm / (2.0 * slope)};
  if (profile == "paraboloid") return Validated(base, "rim circle");
  if (profile == "polynomial") {
    EvenPolynomialProfile<double> polynomial;
    polynomial.num_coefficients = kDefaultPolynomialCoefficients;
    polynomial.coefficients[0] = 1.0 / (4.0 * base.mirror.focal_distance_mm);
    return Validated(WithMirror<EvenPolynomialProfile>(base, polynomial), "rim circle");
  }
  if (profile == "sphere") {
    // z = A - sqrt(A^2 - r^2): slope r / sqrt(A^2 - r^2).
    return Validated(WithMirror<SphereProfile>(base, SphereProfile<double>{rim_mm * std::sqrt(1.0 + 1.0 / (slope * slope))}),
                     "rim circle");
  }
  throw InputError(InputMessage("profile", "", "'" + profile +
                                                     "' cannot start from the rim circle alone (sphere, paraboloid or "
                                                     "polynomial; a hyperboloid needs a guess with its design)"));
}

Sensor ConvertProfile(const Sensor& guess, const std::string& profile) {
  if (profile == guess.profile_name()) return guess;
  if (profile != "sphere" && profile != "paraboloid" && profile != "polynomial" && profile != "hyperboloid")
    throw InputError(InputMessage("profile", "", "unknown profile '" + profile + "' (sphere, paraboloid, polynomial, hyperboloid)"));
  return std::visit(
      [&](const auto& model) -> Sensor {
        // Samples of the guess's sag and slope from the axis to the rim.
        const double rim = model.rim_radius_mm;
        std::vector<SagDerivatives<double>> samples;
        std::vector<double> r2s;
        for (int i = 1; i <= 40; ++i) {
          const double r = rim * i / 40.0;
          r2s.push_back(r * r);
          samples.push_back(model.mirror.template EvaluateSag<double>(r * r));
        }
        // Start every family at the guess's vertex curvature: g'(0) = 1 / (2 R_vertex).
        const double vertex_slope = model.mirror.template EvaluateSag<double>(0.0).dz_ds;
        if (!(vertex_slope > 0.0))
          throw InputError(InputMessage("profile", "", "the guess's mirror is flat or concave at its vertex"));
        const double vertex_radius = 1.0 / (2.0 * vertex_slope);
        if (profile == "paraboloid") {
          const auto p = FitProfile<ParaboloidProfile, 1>(samples, r2s, rim, {vertex_radius / 2.0}, 1);
          return Validated(WithMirror<ParaboloidProfile>(model, ParaboloidProfile<double>{p[0]}), "guess");
        }
        if (profile == "sphere") {
          const auto p = FitProfile<SphereProfile, 1>(samples, r2s, rim, {std::max(vertex_radius, 1.05 * rim)}, 1);
          return Validated(WithMirror<SphereProfile>(model, SphereProfile<double>{p[0]}), "guess");
        }
        if (profile == "hyperboloid") {
          // z = (B / A) (sqrt(A^2 + r^2) - A): vertex radius A^2 / B; start with B = A.
          const auto p = FitProfile<HyperboloidProfile, 2>(samples, r2s, rim, {vertex_radius, vertex_radius}, 2);
          return Validated(WithMirror<HyperboloidProfile>(model, HyperboloidProfile<double>{p[0], p[1]}), "guess");
        }
        std::vector<double> start(kDefaultPolynomialCoefficients, 0.0);
        start[0] = vertex_slope;
        const auto p = FitProfile<EvenPolynomialProfile, kDefaultPolynomialCoefficients>(samples, r2s, rim, start,
                                                                                         kDefaultPolynomialCoefficients);
        return Validated(WithMirror<EvenPolynomialProfile>(
                             model, EvenPolynomialProfile<double>::FromParams(p.data(), kDefaultPolynomialCoefficients)),
                         "guess");
      },
      guess.model());
}

}  // namespace omnical

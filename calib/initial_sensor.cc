#include "calib/initial_sensor.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <type_traits>
#include <variant>

#include "model/input_error.h"

namespace omnical {

namespace {

// Sag (mm) and slope x rim radius (mm) of a profile with these parameters against the
// sampled target.
template <typename Profile>
struct SagResidual {
  Profile shape;  // the family and its parameter count
  double r2, z_mm, slope_times_rim_mm, rim_mm;
  template <typename T>
  bool operator()(T const* const* params, T* residual) const {
    const SagDerivatives<T> g = shape.template WithParams<T>(params[0]).EvaluateSag(T(r2));
    residual[0] = g.z - T(z_mm);
    residual[1] = (T(2.0 * std::sqrt(r2)) * g.dz_ds) * T(rim_mm) - T(slope_times_rim_mm);
    // Beyond the family's domain (a conic that ends before this radius): an invalid step.
    return std::isfinite(ScalarPart(residual[0])) && std::isfinite(ScalarPart(residual[1]));
  }
};

// The profile of start's family (and parameter count) nearest the samples.
template <typename Profile>
Profile FitProfile(const std::vector<SagDerivatives<double>>& samples, const std::vector<double>& r2s, double rim_mm,
                   const Profile& start) {
  std::vector<double> params(start.NumParams());
  start.ToParams(params.data());
  ceres::Problem problem;
  for (size_t i = 0; i < samples.size(); ++i) {
    auto* cost = new ceres::DynamicAutoDiffCostFunction<SagResidual<Profile>, 10>(new SagResidual<Profile>{
        start, r2s[i], samples[i].z, 2.0 * std::sqrt(r2s[i]) * samples[i].dz_ds * rim_mm, rim_mm});
    cost->AddParameterBlock(static_cast<int>(params.size()));
    cost->SetNumResiduals(2);
    problem.AddResidualBlock(cost, nullptr, params.data());
  }
  ceres::Solver::Options options;
  options.max_num_iterations = 200;
  options.function_tolerance = 1e-14;
  options.parameter_tolerance = 1e-14;
  options.logging_type = ceres::SILENT;  // a library never prints
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  return start.WithParams(params.data());
}

// The guess's model with another mirror (target: a model of that mirror and the same lens).
template <typename Model, typename Target>
Target WithMirror(const Model& model, Target out, const typename Target::ProfileType& mirror) {
  out.mirror = mirror;
  out.lens = model.lens;
  out.pose = model.pose;
  out.rim_radius_mm = model.rim_radius_mm;
  out.image_width_px = model.image_width_px;
  out.image_height_px = model.image_height_px;
  out.camera_body_radius_mm = model.camera_body_radius_mm;
  return out;
}

template <typename Profile, typename = void>
constexpr bool kHasKnots = false;
template <typename Profile>
constexpr bool kHasKnots<Profile, std::void_t<decltype(Profile::kMaxKnots)>> = true;

int NumKnots(const Sensor& sensor) {
  return std::visit(
      [](const auto& model) {
        using Profile = std::decay_t<decltype(model.mirror)>;
        if constexpr (kHasKnots<Profile>) return model.mirror.num_knots;
        return 0;
      },
      sensor.model());
}

// How far past the nominal rim a pinhole start's mirror reaches (ThroughPinhole).
constexpr double kPinholeMirrorReach = 1.5;

// An orthographic start's mirror seen through a pinhole on its axis that sees the rim
// theta_rad off the axis, rim_px from the principal point: the vertex R / tan(Theta) - z(R)
// in front of it, the focal length rim_px / tan(Theta), no distortion.
template <template <typename> class Profile>
Catadioptric<double, Profile, PinholeLens> ThroughPinhole(const Catadioptric<double, Profile, OrthographicLens>& model,
                                                          double theta_rad, double rim_px) {
  Catadioptric<double, Profile, PinholeLens> out;
  out.mirror = model.mirror;
  out.rim_radius_mm = model.rim_radius_mm;
  out.image_width_px = model.image_width_px;
  out.image_height_px = model.image_height_px;
  const double rim_mm = model.rim_radius_mm;
  const double rim_sag_mm = model.mirror.template EvaluateSag<double>(rim_mm * rim_mm).z;
  out.pose = {rim_mm / std::tan(theta_rad) - rim_sag_mm, 0.0, 0.0, 0.0, 0.0};
  const double focal_px = rim_px / std::tan(theta_rad);
  out.lens = {focal_px, focal_px, model.lens.cx_px, model.lens.cy_px, 0.0, 0.0, 0.0, 0.0};
  // The mirror reaches past the rim circle's nominal radius, as far as its family allows
  // (a sphere ends at its radius): the focal length and the mirror's size in mm trade
  // off, and the fits shrank the focal length while the shape grew outwards (on
  // rendered/ohte-sph-misaligned-near the nominal rim fell at 418 of the image rim's 500
  // px, and a held-out view's corners beyond it had no ray).
  for (double reach = kPinholeMirrorReach; reach > 1.0; reach -= 0.05) {
    Catadioptric<double, Profile, PinholeLens> wider = out;
    wider.rim_radius_mm = reach * rim_mm;
    if (ValidateSensorModel(wider).empty()) return wider;
  }
  return out;
}

Sensor Validated(SensorModel model, const std::string& what) {
  const std::string problem = ValidateSensorModel(model);
  if (!problem.empty()) throw InputError(InputMessage(what, "profile", "the starting sensor is not valid: " + problem));
  return Sensor(std::move(model));
}

}  // namespace

Sensor SensorFromRimCircle(const RimCircle& rim, int image_width_px, int image_height_px, const std::string& profile,
                           double rim_field_deg, const std::string& lens) {
  if (!(rim.radius_px > 0.0) || !rim.centre_px.allFinite())
    throw InputError(InputMessage("rim circle", "", "no mirror rim found in the images"));
  if (!(rim_field_deg > 10.0 && rim_field_deg < 170.0))
    throw InputError(InputMessage("rim_field_deg", "", "must lie in (10, 170) deg"));
  if (lens != "orthographic" && lens != "pinhole")
    throw InputError(
        InputMessage("lens", "", "the rim circle starts an orthographic or a pinhole lens, not '" + lens + "'"));
  const double rim_mm = kNominalRimRadiusMm;
  const bool pinhole = lens == "pinhole";
  // The rim ray's angle from the lens axis (0 through a telecentric lens); a ray turns by
  // twice the surface's slope angle, so the rim's slope angle is (Omega - Theta) / 2.
  const double theta_rad = pinhole ? kNominalRimViewDeg * M_PI / 180.0 : 0.0;
  const double slope = std::tan(0.5 * (rim_field_deg * M_PI / 180.0 - theta_rad));  // dz/dr at the rim
  if (!(slope > 0.0))
    throw InputError(InputMessage("rim_field_deg", "",
                                  "must exceed the pinhole's view of the rim (" +
                                      std::to_string(static_cast<int>(kNominalRimViewDeg)) + " deg)"));
  Catadioptric<double, ParaboloidProfile, OrthographicLens> base;
  base.lens = {rim.radius_px / rim_mm, rim.centre_px.x(), rim.centre_px.y()};
  base.pose = {100.0, 0.0, 0.0, 0.0, 0.0};  // m: any value in front of the lens (unobservable here)
  base.rim_radius_mm = rim_mm;
  base.image_width_px = image_width_px;
  base.image_height_px = image_height_px;
  // Paraboloid z = r^2 / (4 A): slope r / (2 A).
  base.mirror = {rim_mm / (2.0 * slope)};
  // The mirror of the requested family, through the lens asked for.
  const auto with_lens = [&](const auto& model) -> Sensor {
    if (pinhole) return Validated(ThroughPinhole(model, theta_rad, rim.radius_px), "rim circle");
    return Validated(model, "rim circle");
  };
  if (profile == "paraboloid") return with_lens(base);
  if (profile == "polynomial") {
    EvenPolynomialProfile<double> polynomial;
    polynomial.num_coefficients = kDefaultPolynomialCoefficients;
    polynomial.coefficients[0] = 1.0 / (4.0 * base.mirror.focal_distance_mm);
    return with_lens(WithMirror(base, Catadioptric<double, EvenPolynomialProfile, OrthographicLens>{}, polynomial));
  }
  if (profile == "sphere") {
    // z = A - sqrt(A^2 - r^2): slope r / sqrt(A^2 - r^2).
    return with_lens(WithMirror(base, Catadioptric<double, SphereProfile, OrthographicLens>{},
                                SphereProfile<double>{rim_mm * std::sqrt(1.0 + 1.0 / (slope * slope))}));
  }
  // Any other fitted family that can be smooth at the rim slope: the paraboloid re-expressed.
  if (profile != "hyperboloid") {
    const std::vector<std::string> fitted = ProfileNames(false);
    if (std::find(fitted.begin(), fitted.end(), profile) != fitted.end())
      return ConvertProfile(with_lens(base), profile);
  }
  std::vector<std::string> startable;
  for (const std::string& name : ProfileNames(false))
    if (name != "hyperboloid") startable.push_back(name);
  throw InputError(InputMessage("profile", "", "'" + profile + "' cannot start from the rim circle alone (" +
                                                     JoinChoices(startable) + "; a hyperboloid needs a guess with its design)"));
}

Sensor ConvertProfile(const Sensor& guess, const std::string& profile, int knots) {
  if (knots > 0 && profile != "spline")
    throw InputError(InputMessage("knots", "", "only the spline profile has knots (profile: " + profile + ")"));
  if (profile == guess.profile_name() && (knots <= 0 || NumKnots(guess) == knots)) return guess;
  const std::vector<std::string> fitted = ProfileNames(false);
  if (std::find(fitted.begin(), fitted.end(), profile) == fitted.end())
    throw InputError(InputMessage("profile", "", "unknown profile '" + profile + "' (" + JoinChoices(fitted) + ")"));
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
        std::optional<Sensor> converted;
        ForEachModelType([&](auto tag) {
          using Target = typename decltype(tag)::type;
          using Profile = typename Target::ProfileType;
          using Model = std::decay_t<decltype(model)>;
          if constexpr (kFittedProfile<Profile> && std::is_same_v<typename Target::LensType, typename Model::LensType>) {
            if (converted || profile != Profile::kName) return;
            Profile start = Profile::FromVertexRadius(vertex_radius, rim);
            if constexpr (kHasKnots<Profile>)
              if (knots > 0) start.num_knots = knots;  // FromVertexRadius's knots are all 0
            converted = Validated(WithMirror(model, Target{}, FitProfile(samples, r2s, rim, start)), "guess");
          }
        });
        return *converted;
      },
      guess.model());
}

}  // namespace omnical

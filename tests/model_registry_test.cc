// The model registry (model/model_registry.h) and the even asphere it was proven with:
// every registered lens x profile has test sensors (so the templated harnesses cover it),
// the generated names and parameter lists, and the asphere's conic special cases against
// the sphere, paraboloid and hyperboloid they must reproduce.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <optional>

#include "model/input_error.h"
#include "model/io/sensor_yaml.h"
#include "model/model_registry.h"
#include "model/sensor.h"
#include "test_sensors.h"

namespace omnical {
namespace {

TEST(ModelRegistry, EveryModelTypeHasTestSensors) {
  EXPECT_EQ(testing::ModelTypesWithoutTestSensor(), "");
  EXPECT_EQ(std::variant_size_v<SensorModel>, ProfileNames().size() * LensNames().size());
}

TEST(ModelRegistry, NamesTheChoicesInRegistryOrder) {
  EXPECT_EQ(ProfileNames(), (std::vector<std::string>{"sphere", "polynomial", "hyperboloid", "paraboloid", "tabulated",
                                                      "even_asphere", "spline"}));
  EXPECT_EQ(ProfileNames(false),
            (std::vector<std::string>{"sphere", "polynomial", "hyperboloid", "paraboloid", "even_asphere", "spline"}));
  // The spline is fitted, never designed (no kRimSlopeParam).
  EXPECT_EQ(DesignProfileNames(),
            (std::vector<std::string>{"sphere", "polynomial", "hyperboloid", "paraboloid", "even_asphere"}));
  EXPECT_EQ(LensNames(), (std::vector<std::string>{"pinhole", "orthographic"}));
  EXPECT_EQ(JoinChoices({"a", "b", "c"}), "a, b or c");
}

std::vector<std::string> Names(const std::vector<ParameterInfo>& infos) {
  std::vector<std::string> names;
  for (const ParameterInfo& info : infos) names.push_back(info.name);
  return names;
}

TEST(ModelRegistry, ParameterListsComeFromTheFields) {
  const std::vector<double> params = {50.0, -1.2, 1e-6, 2e-9, -3e-12};
  Catadioptric<double, EvenAsphereProfile, PinholeLens> asphere;
  asphere.mirror = EvenAsphereProfile<double>::FromParams(params.data(), 5);
  const std::vector<ParameterInfo> infos = SensorParameterInfos(asphere);
  EXPECT_EQ(Names(infos), (std::vector<std::string>{"fx_px", "fy_px", "cx_px", "cy_px", "k1", "k2", "p1", "p2", "m_mm",
                                                    "tilt_x_deg", "tilt_y_deg", "decenter_x_mm", "decenter_y_mm", "R_mm",
                                                    "k", "a4", "a6", "a8"}));
  EXPECT_EQ(infos[0].group, ParameterGroup::kFocal);
  EXPECT_EQ(infos[2].group, ParameterGroup::kPrincipalPoint);
  EXPECT_EQ(infos[4].group, ParameterGroup::kDistortion);
  EXPECT_EQ(infos[6].group, ParameterGroup::kTangential);
  EXPECT_EQ(infos[8].group, ParameterGroup::kMirrorDistance);
  EXPECT_TRUE(infos[0].scale_like && infos[8].scale_like && infos[13].scale_like);  // fx, m, R
  EXPECT_FALSE(infos[6].scale_like || infos[14].scale_like || infos[15].scale_like);  // p1, k, a4
  EXPECT_TRUE(HasFreeFormTerms(asphere.mirror));
  EXPECT_FALSE(HasFreeFormTerms(EvenAsphereProfile<double>::FromParams(params.data(), 2)));

  Catadioptric<double, EvenPolynomialProfile, OrthographicLens> polynomial;
  polynomial.mirror = EvenPolynomialProfile<double>::FromParams(params.data(), 3);
  EXPECT_EQ(Names(SensorParameterInfos(polynomial)),
            (std::vector<std::string>{"scale_px_per_mm", "cx_px", "cy_px", "m_mm", "tilt_x_deg", "tilt_y_deg",
                                      "decenter_x_mm", "decenter_y_mm", "c1", "c2", "c3"}));
  Catadioptric<double, TabulatedProfile, PinholeLens> tabulated;
  EXPECT_EQ(SensorParameterInfos(tabulated).size(), 13u);  // no shape parameter
}

// The asphere twin of a conic: the sphere (k = 0, R = A), the paraboloid (k = -1, R = 2 A),
// the hyperboloid (R = A^2 / B, k = -1 - A^2 / B^2); none for the other profiles.
template <template <typename> class Profile, template <typename> class Lens>
std::optional<SensorModel> AsphereTwin(const Catadioptric<double, Profile, Lens>& model) {
  std::vector<double> conic;
  if constexpr (std::is_same_v<Profile<double>, SphereProfile<double>>) {
    conic = {model.mirror.radius_of_curvature_mm, 0.0};
  } else if constexpr (std::is_same_v<Profile<double>, ParaboloidProfile<double>>) {
    conic = {2.0 * model.mirror.focal_distance_mm, -1.0};
  } else if constexpr (std::is_same_v<Profile<double>, HyperboloidProfile<double>>) {
    const double a = model.mirror.a_mm, b = model.mirror.b_mm;
    conic = {a * a / b, -1.0 - a * a / (b * b)};
  } else {
    return std::nullopt;
  }
  Catadioptric<double, EvenAsphereProfile, Lens> twin;
  twin.mirror = EvenAsphereProfile<double>::FromParams(conic.data(), 2);
  twin.lens = model.lens;
  twin.pose = model.pose;
  twin.rim_radius_mm = model.rim_radius_mm;
  twin.image_width_px = model.image_width_px;
  twin.image_height_px = model.image_height_px;
  twin.camera_body_radius_mm = model.camera_body_radius_mm;
  return twin;
}

// k = 0 / -1 / the hyperboloid's k reproduce the sphere, paraboloid and hyperboloid: the
// same pixels for points from the mirror to far away, the same rays for every pixel, to
// 1e-9 px and 1e-9 mm / 1e-12 rad. The two sag formulas agree to rounding (1e-16
// relative); the solvers converge to ~1e-12 px, so 1e-9 px leaves room only for a wrong
// formula (a wrong k or R moves pixels by 1e-3 px and more).
TEST(EvenAsphere, ReproducesTheConicsItGeneralises) {
  int twins = 0, compared = 0;
  for (const testing::NamedSensor& named : testing::AllTestSensors()) {
    const std::optional<SensorModel> twin_model = std::visit([](const auto& m) { return AsphereTwin(m); }, named.model);
    if (!twin_model) continue;
    ++twins;
    ASSERT_EQ(ValidateSensorModel(*twin_model), "") << named.name;
    const Sensor original(named.model), twin(*twin_model);
    double worst_px = 0.0, worst_origin_mm = 0.0, worst_direction = 0.0;
    for (double v = 5.0; v < 1000.0; v += 23.0) {
      for (double u = 5.0; u < 1000.0; u += 23.0) {
        Eigen::Vector3d origin, direction, twin_origin, twin_direction;
        const ProjectionStatus status = original.Unproject({u, v}, &origin, &direction);
        ASSERT_EQ(twin.Unproject({u, v}, &twin_origin, &twin_direction), status) << named.name << " " << u << "," << v;
        if (status != ProjectionStatus::kOk) continue;
        worst_origin_mm = std::max(worst_origin_mm, (origin - twin_origin).norm());
        worst_direction = std::max(worst_direction, (direction - twin_direction).norm());
        for (double distance_rims : {0.05, 1.0, 7.0, 1000.0}) {
          const Eigen::Vector3d point = origin + distance_rims * testing::kRimMm * direction;
          Eigen::Vector2d pixel, twin_pixel;
          ASSERT_EQ(original.Project(point, &pixel), ProjectionStatus::kOk) << named.name;
          ASSERT_EQ(twin.Project(point, &twin_pixel), ProjectionStatus::kOk) << named.name;
          worst_px = std::max(worst_px, (pixel - twin_pixel).norm());
          ++compared;
        }
      }
    }
    EXPECT_LT(worst_px, 1e-9) << named.name;
    char text[64];
    std::snprintf(text, sizeof text, "%.3g px, %.3g mm, %.3g", worst_px, worst_origin_mm, worst_direction);
    RecordProperty(named.name, text);
    EXPECT_LT(worst_origin_mm, 1e-9) << named.name;
    EXPECT_LT(worst_direction, 1e-12) << named.name;
  }
  EXPECT_EQ(twins, 12);  // three conics x two lenses x aligned / misaligned
  EXPECT_GT(compared, 12 * 4 * 1000);
}

// The sag and its derivatives against the formula written out, at a few radii: the
// s-derivatives the solvers use are the conic's and the terms' exactly.
TEST(EvenAsphere, SagMatchesTheIsoFormula) {
  const std::vector<double> params = {60.0, -0.6, 3e-7, -2e-10, 1e-13};
  const EvenAsphereProfile<double> asphere = EvenAsphereProfile<double>::FromParams(params.data(), 5);
  const double c = 1.0 / 60.0, k = -0.6;
  auto sag = [&](double r) {
    return c * r * r / (1.0 + std::sqrt(1.0 - (1.0 + k) * c * c * r * r)) + 3e-7 * std::pow(r, 4) -
           2e-10 * std::pow(r, 6) + 1e-13 * std::pow(r, 8);
  };
  for (double r : {0.0, 5.0, 20.0, 45.0, 70.0}) {
    const SagDerivatives<double> g = asphere.EvaluateSag(r * r);
    EXPECT_NEAR(g.z, sag(r), 1e-12 * (1.0 + std::abs(sag(r)))) << r;
    // dz/dr by central differences against 2 r g'; d2z/dr2 against 2 g' + 4 r^2 g''.
    const double h = 1e-4;
    const double dz_dr = (sag(r + h) - sag(r - h)) / (2.0 * h);
    const double d2z_dr2 = (sag(r + h) - 2.0 * sag(r) + sag(r - h)) / (h * h);
    double slope, curvature;
    RadialSlopes(g, r, &slope, &curvature);
    EXPECT_NEAR(slope, dz_dr, 1e-8) << r;
    EXPECT_NEAR(curvature, d2z_dr2, 1e-5) << r;
  }
  // Where the conic ends: R / sqrt(1 + k) for an ellipsoid; nowhere for a hyperboloid.
  EXPECT_NEAR(asphere.MaxRadiusMm(), 60.0 / std::sqrt(0.4), 1e-12);
  EXPECT_EQ(asphere.CheckDomain(94.0), "");
  EXPECT_NE(asphere.CheckDomain(95.0), "");
  const std::vector<double> hyperbolic = {60.0, -3.0};
  EXPECT_TRUE(std::isinf(EvenAsphereProfile<double>::FromParams(hyperbolic.data(), 2).MaxRadiusMm()));
}

TEST(EvenAsphere, ReadsAndWritesItsSensorFileFields) {
  const std::string text =
      "camera: { model: pinhole, image_size: [1000, 1000], fx: 1500, fy: 1500, cx: 499.5, cy: 499.5 }\n"
      "mirror: { profile: even_asphere, rim_radius: 40, R: 36, k: -1.5, a: [1e-5, -2e-9] }\n"
      "pose: { m: 160 }\n";
  const Sensor sensor = ParseSensorYaml(text, "asphere.yaml");
  ASSERT_STREQ(sensor.profile_name(), "even_asphere");
  const auto& model = std::get<Catadioptric<double, EvenAsphereProfile, PinholeLens>>(sensor.model());
  EXPECT_EQ(model.mirror.vertex_radius_mm, 36.0);
  EXPECT_EQ(model.mirror.conic_constant, -1.5);
  ASSERT_EQ(model.mirror.num_terms, 2);
  EXPECT_EQ(model.mirror.terms[1], -2e-9);
  const Sensor again = ParseSensorYaml(SensorYamlText(sensor), "again.yaml");
  EXPECT_EQ(SensorYamlText(again), SensorYamlText(sensor));
  // No terms: a pure conic; a bad field is named.
  EXPECT_NO_THROW(ParseSensorYaml(
      "camera: { model: pinhole, image_size: [1000, 1000], fx: 1500, fy: 1500, cx: 499.5, cy: 499.5 }\n"
      "mirror: { profile: even_asphere, rim_radius: 40, R: 36, k: -1.5 }\npose: { m: 160 }\n",
      "conic.yaml"));
  try {
    ParseSensorYaml(
        "camera: { model: pinhole, image_size: [1000, 1000], fx: 1500, fy: 1500, cx: 499.5, cy: 499.5 }\n"
        "mirror: { profile: even_asphere, rim_radius: 40, R: -36, k: 0 }\npose: { m: 160 }\n",
        "bad.yaml");
    ADD_FAILURE() << "a negative R was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("bad.yaml: mirror.R: ", 0), 0u) << e.what();
  }
  try {
    ParseSensorYaml(
        "camera: { model: pinhole, image_size: [1000, 1000], fx: 1500, fy: 1500, cx: 499.5, cy: 499.5 }\n"
        "mirror: { profile: even_asphere, rim_radius: 40, R: 36, k: 0, a: [1, 2, 3, 4, 5, 6, 7, 8, 9] }\n"
        "pose: { m: 160 }\n",
        "long.yaml");
    ADD_FAILURE() << "nine terms were accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("long.yaml: mirror.a: ", 0), 0u) << e.what();
  }
}

}  // namespace
}  // namespace omnical

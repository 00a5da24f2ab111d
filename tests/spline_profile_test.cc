// The spline profile (model/spline_profile.h) against what it must be, with expected
// values from outside its code: the polynomial profile it reduces to, the textbook
// values of a uniform cubic B-spline at its knots, the closed forms of the shipped
// profiles it approximates, and central differences.
#include <gtest/gtest.h>

#include <ceres/jet.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "calib/initial_sensor.h"
#include "model/input_error.h"
#include "model/io/sensor_yaml.h"
#include "model/sensor.h"
#include "test_sensors.h"

namespace omnical {
namespace {

using testing::kRimMm;

SplineProfile<double> Spline(double c1_per_mm, const std::vector<double>& knots_mm, double span_mm) {
  std::vector<double> params = {c1_per_mm};
  params.insert(params.end(), knots_mm.begin(), knots_mm.end());
  SplineProfile<double> spline = SplineProfile<double>::FromParams(params.data(), static_cast<int>(params.size()));
  spline.span_mm = span_mm;
  return spline;
}

// The E-DI polynomial of the test sensors: g(s) = c1 s + c2 s^2 + c3 s^3, a cubic in s.
const std::vector<double> kEdi = {0.6409 / kRimMm, 0.1550 / std::pow(kRimMm, 3), -0.01 / std::pow(kRimMm, 5)};

// The control values that make a uniform cubic B-spline (spacing h) equal a cubic p:
// Marsden's identity, v_j = blossom(s_j - h, s_j, s_j + h) = p(s_j) - h^2 p''(s_j) / 6.
std::vector<double> MarsdenKnots(double c2, double c3, int count, double span_mm) {
  const double h = span_mm * span_mm / (count - 1);
  std::vector<double> knots;
  for (int j = 1; j <= count; ++j) {
    const double s = j * h;
    knots.push_back(c2 * s * s + c3 * s * s * s - h * h * (2.0 * c2 + 6.0 * c3 * s) / 6.0);
  }
  return knots;
}

// The same sensor with another mirror.
template <template <typename> class To, template <typename> class From, template <typename> class Lens>
Catadioptric<double, To, Lens> WithMirror(const Catadioptric<double, From, Lens>& model, const To<double>& mirror) {
  Catadioptric<double, To, Lens> out;
  out.mirror = mirror;
  out.lens = model.lens;
  out.pose = model.pose;
  out.rim_radius_mm = model.rim_radius_mm;
  out.image_width_px = model.image_width_px;
  out.image_height_px = model.image_height_px;
  return out;
}

// The largest pixel and ray difference of two sensors over the image (rays of every 23rd
// pixel, points on them from 0.05 to 1000 rims away); both must agree on which pixels see
// the mirror.
struct Difference {
  double px = 0.0, origin_mm = 0.0, direction = 0.0;
  int compared = 0;
};
Difference Compare(const Sensor& a, const Sensor& b) {
  Difference worst;
  for (double v = 5.0; v < 1000.0; v += 23.0) {
    for (double u = 5.0; u < 1000.0; u += 23.0) {
      Eigen::Vector3d origin, direction, b_origin, b_direction;
      const ProjectionStatus status = a.Unproject({u, v}, &origin, &direction);
      EXPECT_EQ(b.Unproject({u, v}, &b_origin, &b_direction), status) << u << "," << v;
      if (status != ProjectionStatus::kOk) continue;
      worst.origin_mm = std::max(worst.origin_mm, (origin - b_origin).norm());
      worst.direction = std::max(worst.direction, (direction - b_direction).norm());
      for (double distance_rims : {0.05, 1.0, 7.0, 1000.0}) {
        const Eigen::Vector3d point = origin + distance_rims * kRimMm * direction;
        Eigen::Vector2d pixel, b_pixel;
        EXPECT_EQ(a.Project(point, &pixel), ProjectionStatus::kOk);
        EXPECT_EQ(b.Project(point, &b_pixel), ProjectionStatus::kOk);
        worst.px = std::max(worst.px, (pixel - b_pixel).norm());
        ++worst.compared;
      }
    }
  }
  return worst;
}

template <template <typename> class Lens>
void ExpectTwinsProjectAlike(const std::string& lens) {
  for (bool misaligned : {false, true}) {
    const std::string name = lens + (misaligned ? "/misaligned" : "/aligned");
    // c1 alone: the paraboloid z = c1 r^2 as a polynomial, and the spline with knots 0.
    const EvenPolynomialProfile<double> parabola = EvenPolynomialProfile<double>::FromParams(kEdi.data(), 1);
    const auto polynomial = testing::MakeModel<EvenPolynomialProfile, Lens>(parabola, 180.0, misaligned);
    for (int knots : {4, 8, 16}) {
      const Sensor spline(WithMirror(polynomial, Spline(kEdi[0], std::vector<double>(knots, 0.0), kRimMm)));
      ASSERT_EQ(ValidateSensorModel(spline.model()), "") << name;
      const Difference d = Compare(Sensor(polynomial), spline);
      EXPECT_LT(d.px, 1e-9) << name << " " << knots << " knots";
      EXPECT_LT(d.origin_mm, 1e-9) << name;
      EXPECT_LT(d.direction, 1e-12) << name;
      EXPECT_GT(d.compared, 4 * 1000) << name;
    }
    // The E-DI polynomial, a cubic in s, is a spline too (Marsden's knots, not fitted).
    const auto edi = testing::MakeModel<EvenPolynomialProfile, Lens>(
        EvenPolynomialProfile<double>::FromParams(kEdi.data(), 3), 3.919 * kRimMm, misaligned);
    const Sensor spline(WithMirror(edi, Spline(kEdi[0], MarsdenKnots(kEdi[1], kEdi[2], 6, kRimMm), kRimMm)));
    const Difference d = Compare(Sensor(edi), spline);
    EXPECT_LT(d.px, 1e-9) << name << " E-DI";
    EXPECT_LT(d.origin_mm, 1e-9) << name << " E-DI";
  }
}

// (a) With every knot 0 the spline's sag is c1 s + 0: the polynomial's c1 s, c1 and 0
// bit for bit (the B-spline's terms are exact zeros), so both sensors run the same solver
// iterations; and a cubic in s (the E-DI mirror) is reproduced to rounding by its
// Marsden knots. 1e-9 px leaves room only for rounding (the solvers converge to ~1e-12
// px); a wrong basis or phantom value moves pixels by 1e-3 px and more.
TEST(SplineProfile, ProjectsLikeThePolynomialsItContains) {
  ExpectTwinsProjectAlike<PinholeLens>("pinhole");
  ExpectTwinsProjectAlike<OrthographicLens>("orthographic");
}

// (b) C2: at every knot position s_j and at the span end, the limits from either side
// equal the uniform cubic B-spline's textbook values there,
//   B = (v_j-1 + 4 v_j + v_j+1) / 6,  B' = (v_j+1 - v_j-1) / 2h,  B'' = (v_j-1 - 2 v_j + v_j+1) / h^2,
// (and g(0) = 0, g'(0) = c1, g''(0) = 3 v_1 / h^2 at the axis, with the phantoms). Each
// side is probed only with points on that side: the returned g, g', g'' at s_j -+ 1e-9 h
// (against the limits' Taylor lines), and one-sided second-order differences of g and g'
// over 1e-4 of a segment (exact for g', a quadratic in s; d^2 g''' / 3 ~ 1e-12 for g),
// so a jump in a derivative of 1e-6 of its size cannot hide.
TEST(SplineProfile, IsTwiceContinuouslyDifferentiableAcrossKnots) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> value(-0.3, 0.3);
  std::vector<SplineProfile<double>> splines = {testing::BumpedSplineProfile()};
  for (int n : {4, 9, 16}) {
    std::vector<double> knots(n);
    for (double& v : knots) v = value(rng);
    splines.push_back(Spline(0.011, knots, 40.0));
  }
  for (const SplineProfile<double>& spline : splines) {
    const int n = spline.num_knots;
    const double h = spline.span_mm * spline.span_mm / (n - 1), c1 = spline.c1_per_mm;
    auto v = [&](int j) { return j >= 1 ? spline.knots_mm[j - 1] : j == 0 ? -0.5 * spline.knots_mm[0] : spline.knots_mm[0]; };
    for (int j = 0; j <= n - 1; ++j) {
      const double s = j * h;
      const double g = c1 * s + (v(j - 1) + 4.0 * v(j) + v(j + 1)) / 6.0;
      const double dg = c1 + (v(j + 1) - v(j - 1)) / (2.0 * h);
      const double ddg = (v(j - 1) - 2.0 * v(j) + v(j + 1)) / (h * h);
      const std::string where = std::to_string(n) + " knots, s_" + std::to_string(j);
      if (j == 0) {
        EXPECT_NEAR(g, 0.0, 1e-15) << where;
        EXPECT_NEAR(dg, c1, 1e-15) << where;
        EXPECT_NEAR(ddg, 3.0 * spline.knots_mm[0] / (h * h), 1e-18) << where;
      }
      for (double side : {-1.0, 1.0}) {
        if (j == 0 && side < 0.0) continue;  // s = r^2 >= 0
        const std::string at = where + (side < 0.0 ? " from the left" : " from the right");
        const double delta = side * 1e-9 * h;
        const SagDerivatives<double> near = spline.EvaluateSag(s + delta);
        EXPECT_NEAR(near.z, g + delta * dg, 1e-12 * (1.0 + std::abs(g))) << at;
        EXPECT_NEAR(near.dz_ds, dg + delta * ddg, 1e-12 * std::abs(c1)) << at;
        EXPECT_NEAR(near.d2z_ds2, ddg, 1e-7 * std::abs(c1) / h) << at;
        const double d = side * 1e-4 * h;
        const SagDerivatives<double> at1 = spline.EvaluateSag(s + d), at2 = spline.EvaluateSag(s + 2.0 * d);
        const SagDerivatives<double> at0 = spline.EvaluateSag(s + side * 1e-12 * h);
        EXPECT_NEAR((-3.0 * at0.z + 4.0 * at1.z - at2.z) / (2.0 * d), dg, 1e-6 * std::abs(c1)) << at;
        EXPECT_NEAR((-3.0 * at0.dz_ds + 4.0 * at1.dz_ds - at2.dz_ds) / (2.0 * d), ddg, 1e-6 * std::abs(c1) / h) << at;
      }
    }
    // Past the span: the end's quadratic in s, g''' = 0 (its g'' is constant).
    const double end = spline.span_mm * spline.span_mm;
    EXPECT_EQ(spline.EvaluateSag(1.5 * end).d2z_ds2, spline.EvaluateSag(3.0 * end).d2z_ds2);
  }
}

// The spline nearest (least squares over 2000 radii) to a profile's sag over the rim.
template <typename Profile>
double FittedSagError(const Profile& profile, int knots) {
  const SplineProfile<double> family = Spline(1.0, std::vector<double>(knots, 0.0), kRimMm);
  constexpr int kSamples = 2000;
  Eigen::MatrixXd design(kSamples, knots + 1);
  Eigen::VectorXd sag(kSamples);
  for (int i = 0; i < kSamples; ++i) {
    const double r = kRimMm * (i + 0.5) / kSamples;
    sag(i) = profile.EvaluateSag(r * r).z;
    for (int p = 0; p <= knots; ++p) {  // the spline is linear in its parameters
      std::vector<double> unit(knots + 1, 0.0);
      unit[p] = 1.0;
      design(i, p) = family.WithParams(unit.data()).EvaluateSag(r * r).z;
    }
  }
  const Eigen::VectorXd params = design.colPivHouseholderQr().solve(sag);
  return (design * params - sag).cwiseAbs().maxCoeff();
}

// (c) It represents the other shipped profiles: a cubic spline's error is O(h^4 g''''),
// so 12 -> 16 knots (h 11 -> 15 segments) divides it by (15/11)^4 = 3.5. The steepest
// case is the Ohte sphere (A = 1.138 rim: slope 1.8 at the rim, g'''' large there):
// 1.2e-4 mm with 12 knots, 3.4e-5 with 16. Its sag is 19 mm, so 12 knots hold it to
// 6e-6 relative, 0.01 px at the rim of the test sensors; the E-DI polynomial is exact.
TEST(SplineProfile, RepresentsTheShippedProfiles) {
  const SphereProfile<double> ohte_sphere{1.138 * kRimMm};
  const double sphere_12 = FittedSagError(ohte_sphere, 12), sphere_16 = FittedSagError(ohte_sphere, 16);
  EXPECT_LT(sphere_12, 2e-4);
  EXPECT_LT(sphere_16, 5e-5);
  EXPECT_NEAR(sphere_12 / sphere_16, std::pow(15.0 / 11.0, 4), 0.5);
  EXPECT_LT(FittedSagError(SphereProfile<double>{1.5 * kRimMm}, 12), 2e-6);
  EXPECT_LT(FittedSagError(HyperboloidProfile<double>{0.7407 * kRimMm, 1.698 * kRimMm}, 12), 5e-5);
  EXPECT_LT(FittedSagError(EvenPolynomialProfile<double>::FromParams(kEdi.data(), 3), 4), 1e-12);
  // The table of the E-DI sampled to 1.05 rim: its natural end (g'' = 0 there) makes it
  // no single cubic near the rim.
  EXPECT_LT(FittedSagError(testing::SampledEdiProfile(), 12), 5e-7);
  RecordProperty("ohte_sphere_12_knots_mm", std::to_string(sphere_12));
  RecordProperty("ohte_sphere_16_knots_mm", std::to_string(sphere_16));
}

// (d) Jets through EvaluateSag (over c1, every knot and s itself, in every segment and
// past the span) against central differences. The sag is linear in the parameters and a
// polynomial of degree 3 in s, so central differences are exact but for rounding.
TEST(SplineProfile, JetDerivativesAgreeWithCentralDifferences) {
  using Jet = ceres::Jet<double, 18>;
  const SplineProfile<double> spline = testing::BumpedSplineProfile();
  const int count = spline.NumParams();
  std::vector<double> params(count);
  spline.ToParams(params.data());
  const double end = kRimMm * kRimMm;
  int checked = 0;
  for (double s : {0.0, 0.03 * end, 0.37 * end, 0.61 * end, 0.999 * end, 1.2 * end}) {
    std::vector<Jet> jets(count);
    for (int k = 0; k < count; ++k) jets[k] = Jet(params[k], k);
    const SagDerivatives<Jet> g = spline.WithParams<Jet>(jets.data()).EvaluateSag(Jet(s, count));
    for (int k = 0; k <= count; ++k) {
      if (k == count && s == 0.0) continue;  // s = r^2 >= 0: no central difference at the axis
      const double step = k < count ? 1e-4 * std::max(std::abs(params[k]), 1e-3) : 1e-3 * end / 16.0;
      std::vector<double> plus = params, minus = params;
      double s_plus = s, s_minus = s;
      if (k < count) {
        plus[k] += step, minus[k] -= step;
      } else {
        s_plus += step, s_minus -= step;
      }
      const SagDerivatives<double> gp = spline.WithParams(plus.data()).EvaluateSag(s_plus);
      const SagDerivatives<double> gm = spline.WithParams(minus.data()).EvaluateSag(s_minus);
      const double width = 2.0 * step;
      const std::string what = "s = " + std::to_string(s) + ", parameter " + std::to_string(k);
      EXPECT_NEAR(g.z.v[k], (gp.z - gm.z) / width, 1e-8 * (1.0 + std::abs(g.z.v[k]))) << what;
      EXPECT_NEAR(g.dz_ds.v[k], (gp.dz_ds - gm.dz_ds) / width, 1e-8 * (1e-3 + std::abs(g.dz_ds.v[k]))) << what;
      EXPECT_NEAR(g.d2z_ds2.v[k], (gp.d2z_ds2 - gm.d2z_ds2) / width, 1e-8 * (1e-8 + std::abs(g.d2z_ds2.v[k]))) << what;
      ++checked;
    }
    // And the s-derivative the Jet carries is the returned slope.
    EXPECT_NEAR(g.z.v[count], g.dz_ds.a, 1e-15) << s;
  }
  EXPECT_EQ(checked, 6 * (count + 1) - 1);
}

TEST(SplineProfile, RefusesWhatIsNoMirror) {
  const SplineProfile<double> good = testing::BumpedSplineProfile();
  EXPECT_EQ(good.CheckDomain(kRimMm), "");
  EXPECT_EQ(good.CheckDomain(1.15 * kRimMm), "");  // past the span too
  auto starts = [](const std::string& text, const std::string& prefix) { return text.rfind(prefix, 0) == 0; };
  SplineProfile<double> bad = good;
  for (double span : {0.0, -40.0, std::nan(""), HUGE_VAL}) {
    bad.span_mm = span;
    EXPECT_TRUE(starts(bad.CheckDomain(kRimMm), "span: ")) << span;
  }
  bad = good;
  bad.c1_per_mm = 0.0;
  EXPECT_TRUE(starts(bad.CheckDomain(kRimMm), "c1: "));
  bad = good;
  bad.knots_mm[2] = NAN;
  EXPECT_TRUE(starts(bad.CheckDomain(kRimMm), "knots: must be finite"));
  for (int n : {3, 17}) {  // the reader caps the list; this is what a program could set
    bad = good;
    bad.num_knots = n;
    EXPECT_TRUE(starts(bad.CheckDomain(kRimMm), "knots: must list")) << n;
  }
  // A dent: the bump scaled until z'' or z' <= 0 somewhere before the rim. The exact test
  // (minima of quadratics) and 20000 samples of z' and z'' must find the same threshold.
  auto convex_by_sampling = [](const SplineProfile<double>& spline, double rim_mm) {
    for (int i = 1; i <= 20000; ++i) {
      const double r = rim_mm * i / 20000.0;
      double slope = 0.0, curvature = 0.0;
      RadialSlopes(spline.EvaluateSag(r * r), r, &slope, &curvature);
      if (!(slope > 0.0 && curvature > 0.0)) return false;
    }
    return true;
  };
  double exact_threshold = 0.0, sampled_threshold = 0.0;
  for (double scale = 1.0; scale < 20.0; scale += 0.01) {
    SplineProfile<double> dented = good;
    for (int k = 0; k < dented.num_knots; ++k) dented.knots_mm[k] = -scale * good.knots_mm[k];
    if (exact_threshold == 0.0 && !dented.CheckDomain(kRimMm).empty()) {
      exact_threshold = scale;
      EXPECT_TRUE(starts(dented.CheckDomain(kRimMm), "knots: the profile is not convex")) << dented.CheckDomain(kRimMm);
    }
    if (sampled_threshold == 0.0 && !convex_by_sampling(dented, kRimMm)) sampled_threshold = scale;
  }
  ASSERT_GT(exact_threshold, 0.0);
  EXPECT_NEAR(exact_threshold, sampled_threshold, 0.011);
}

const char* kCamera = "camera: { model: orthographic, image_size: [1000, 1000], scale_px_per_mm: 10, cx: 499.5, cy: 499.5 }\n";

TEST(SplineProfile, ReadsAndWritesItsSensorFileFields) {
  const Sensor sensor = ParseSensorYaml(
      std::string(kCamera) +
          "mirror: { profile: spline, rim_radius: 43.9, span: 40, c1: 0.0114, knots: [0.2, 0.5, 0.4, 0.1, 0.2] }\n"
          "pose: { m: 180 }\n",
      "spline.yaml");
  ASSERT_STREQ(sensor.profile_name(), "spline");
  const auto& model = std::get<Catadioptric<double, SplineProfile, OrthographicLens>>(sensor.model());
  EXPECT_EQ(model.mirror.span_mm, 40.0);
  EXPECT_EQ(model.mirror.c1_per_mm, 0.0114);
  ASSERT_EQ(model.mirror.num_knots, 5);
  EXPECT_EQ(model.mirror.knots_mm[4], 0.2);
  const std::string text = SensorYamlText(sensor);
  EXPECT_NE(text.find("span: 40"), std::string::npos) << text;
  EXPECT_EQ(SensorYamlText(ParseSensorYaml(text, "again.yaml")), text);

  auto refusal = [](const std::string& mirror) -> std::string {
    try {
      ParseSensorYaml(std::string(kCamera) + "mirror: " + mirror + "\npose: { m: 180 }\n", "bad.yaml");
    } catch (const InputError& e) {
      return e.what();
    }
    return "accepted";
  };
  EXPECT_EQ(refusal("{ profile: spline, rim_radius: 43.9, c1: 0.0114, knots: [0, 0, 0, 0] }").rfind("bad.yaml: mirror.span: ", 0),
            0u);
  EXPECT_EQ(refusal("{ profile: spline, rim_radius: 43.9, span: -1, c1: 0.0114, knots: [0, 0, 0, 0] }")
                .rfind("bad.yaml: mirror.span: ", 0),
            0u);
  EXPECT_EQ(refusal("{ profile: spline, rim_radius: 43.9, span: 40, c1: 0.0114, knots: [0, 0, 0] }")
                .rfind("bad.yaml: mirror.knots: ", 0),
            0u);
  EXPECT_EQ(refusal("{ profile: spline, rim_radius: 43.9, span: 40, c1: 0.0114, knots: [0, -9, 0, 0] }")
                .rfind("bad.yaml: mirror.knots: the profile is not convex", 0),
            0u);
  EXPECT_EQ(refusal("{ profile: spline, rim_radius: 43.9, span: 40, c1: 0.0114, knots: [0, 0, 0, 0], table: x.csv }")
                .rfind("bad.yaml: mirror", 0),
            0u);
}

// Converting a guess (calib/initial_sensor.cc: least squares on sag and slope) from the
// E-DI polynomial gives its Marsden knots over the rim: the exact representation.
TEST(SplineProfile, ConvertsAGuessOfAnotherProfile) {
  const auto edi = testing::MakeModel<EvenPolynomialProfile, OrthographicLens>(
      EvenPolynomialProfile<double>::FromParams(kEdi.data(), 3), 180.0, false);
  const Sensor spline = ConvertProfile(Sensor(edi), "spline");
  const auto& model = std::get<Catadioptric<double, SplineProfile, OrthographicLens>>(spline.model());
  EXPECT_EQ(model.mirror.span_mm, kRimMm);
  EXPECT_NEAR(model.mirror.c1_per_mm, kEdi[0], 1e-12);
  const std::vector<double> expected =
      MarsdenKnots(kEdi[1], kEdi[2], SplineProfile<double>::kDefaultKnots, kRimMm);
  ASSERT_EQ(model.mirror.num_knots, static_cast<int>(expected.size()));
  for (size_t k = 0; k < expected.size(); ++k) EXPECT_NEAR(model.mirror.knots_mm[k], expected[k], 1e-8) << k;
  // From a paraboloid: its c1 = 1 / (4 A) and every knot 0.
  const auto paraboloid = testing::MakeModel<ParaboloidProfile, OrthographicLens>({0.5 * kRimMm}, 180.0, false);
  const Sensor converted = ConvertProfile(Sensor(paraboloid), "spline");
  const auto& from_paraboloid = std::get<Catadioptric<double, SplineProfile, OrthographicLens>>(converted.model());
  EXPECT_NEAR(from_paraboloid.mirror.c1_per_mm, 0.5 / kRimMm, 1e-14);
  for (int k = 0; k < from_paraboloid.mirror.num_knots; ++k) EXPECT_NEAR(from_paraboloid.mirror.knots_mm[k], 0.0, 1e-10);
}

}  // namespace
}  // namespace omnical

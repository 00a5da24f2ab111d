// Profile formulas: the slopes and curvatures each profile returns are the derivatives
// of its sag (central differences), and the tabulated spline reproduces a known curve.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "model/input_error.h"
#include "model/mirror_profiles.h"
#include "model/io/profile_table.h"
#include "model/tabulated_profile.h"
#include "test_sensors.h"

namespace omnical {
namespace {

template <typename Profile>
void ExpectDerivativesConsistent(const Profile& profile, double max_radius) {
  for (double r = 0.0; r <= max_radius; r += max_radius / 40.0) {
    const double h = 1e-4;
    const double s = r * r;
    const SagDerivatives<double> at = profile.EvaluateSag(s);
    const SagDerivatives<double> plus = profile.EvaluateSag(s + h), minus = profile.EvaluateSag(std::max(s - h, 0.0));
    const double denominator = s >= h ? 2.0 * h : s + h;
    // Central differences in s with h = 1e-4 mm^2: truncation ~h^2 g''' ~ 1e-10.
    EXPECT_NEAR(at.dz_ds, (plus.z - minus.z) / denominator, 1e-7 * (1.0 + std::abs(at.dz_ds))) << "r = " << r;
    EXPECT_NEAR(at.d2z_ds2, (plus.dz_ds - minus.dz_ds) / denominator, 1e-6 * (1.0 + std::abs(at.d2z_ds2)))
        << "r = " << r;
  }
}

TEST(Profiles, SagDerivativesAreConsistent) {
  ExpectDerivativesConsistent(SphereProfile<double>{50.0}, 45.0);
  ExpectDerivativesConsistent(
      EvenPolynomialProfile<double>::FromParams(std::vector<double>{0.0146, 1.83e-6, -6.1e-11}.data(), 3), 45.0);
  ExpectDerivativesConsistent(HyperboloidProfile<double>{32.5, 74.5}, 45.0);
  ExpectDerivativesConsistent(ParaboloidProfile<double>{22.0}, 45.0);
  ExpectDerivativesConsistent(testing::SampledEdiProfile(), 45.0);
}

// The closed forms of the seed's Table 1 at r = 1 (normalised units).
TEST(Profiles, MatchTheSeedFormulas) {
  const double a = 1.138;
  const SphereProfile<double> sphere{a};
  double slope = 0.0, curvature = 0.0;
  RadialSlopes(sphere.EvaluateSag(1.0), 1.0, &slope, &curvature);
  EXPECT_NEAR(sphere.EvaluateSag(1.0).z, a - std::sqrt(a * a - 1.0), 1e-15);
  EXPECT_NEAR(slope, 1.0 / std::sqrt(a * a - 1.0), 1e-14);
  EXPECT_NEAR(curvature, a * a / std::pow(a * a - 1.0, 1.5), 1e-13);
  const HyperboloidProfile<double> hyperboloid{0.7407, 1.698};
  RadialSlopes(hyperboloid.EvaluateSag(1.0), 1.0, &slope, &curvature);
  const double root = std::sqrt(0.7407 * 0.7407 + 1.0);
  EXPECT_NEAR(slope, (1.698 / 0.7407) / root, 1e-14);
  EXPECT_NEAR(curvature, 0.7407 * 1.698 / std::pow(root, 3), 1e-14);
}

// A natural cubic spline in r^2 through 121 samples of the E-DI polynomial: between
// knots (spacing ~0.4 mm) the sag error is O(h^4 g'''') ~ 1e-9 mm.
TEST(TabulatedProfile, InterpolatesASmoothProfile) {
  const TabulatedProfile<double> table = testing::SampledEdiProfile();
  const EvenPolynomialProfile<double> edi = EvenPolynomialProfile<double>::FromParams(
      std::vector<double>{0.6409 / testing::kRimMm, 0.1550 / std::pow(testing::kRimMm, 3),
                          -0.01 / std::pow(testing::kRimMm, 5)}
          .data(),
      3);
  double worst_sag = 0.0, worst_slope = 0.0;
  for (double r = 0.05; r < testing::kRimMm; r += 0.173) {
    double slope_table = 0.0, slope_true = 0.0, c = 0.0;
    RadialSlopes(table.EvaluateSag(r * r), r, &slope_table, &c);
    RadialSlopes(edi.EvaluateSag(r * r), r, &slope_true, &c);
    worst_sag = std::max(worst_sag, std::abs(table.EvaluateSag(r * r).z - edi.EvaluateSag(r * r).z));
    worst_slope = std::max(worst_slope, std::abs(slope_table - slope_true));
  }
  EXPECT_LT(worst_sag, 1e-6);
  EXPECT_LT(worst_slope, 1e-5);
}

// A cone point (the reflection ODE's vertex when the centre pixel looks off the axis):
// z = k r + c r^2 + e r^3 tabulated on 400 rows with its slope. Splined in r, clamped to
// k at the vertex, the sag, slope and curvature follow it to the axis; a spline in r^2
// cannot (z ~ k sqrt(s)), which is what the uniform design's law lost near the centre.
TEST(TabulatedProfile, ConePointFollowsTheTableToTheAxis) {
  const double k = 0.23, c = 0.004, e = 1e-5, rim = 30.0;
  auto sag = [&](double r) { return r * (k + r * (c + r * e)); };
  auto slope = [&](double r) { return k + r * (2.0 * c + 3.0 * e * r); };
  std::vector<double> r, z;
  for (int i = 0; i < 400; ++i) r.push_back(rim * i / 399.0), z.push_back(sag(r.back()));
  const ProfileSpline cone(r, z, slope(rim), k);
  ASSERT_TRUE(cone.cone_tip());
  for (double x : {1e-6, 1e-3, 0.05, 0.2, 3.0, 17.3, 29.9}) {
    const SagDerivatives<double> g = cone.Evaluate(x * x);
    double dz_dr = 0.0, d2z_dr2 = 0.0;
    RadialSlopes(g, x, &dz_dr, &d2z_dr2);
    // The cubic through exact samples of a cubic: round-off only, growing as 1/r in the
    // s-derivatives' conversion near the axis.
    EXPECT_NEAR(g.z, sag(x), 1e-12) << "r = " << x;
    EXPECT_NEAR(dz_dr, slope(x), 1e-9) << "r = " << x;
    EXPECT_NEAR(d2z_dr2, 2.0 * c + 6.0 * e * x, 1e-9 / x) << "r = " << x;
  }
  // The same table without its slope column is a smooth r^2 spline and misses the cone
  // near the axis by orders of magnitude more.
  const ProfileSpline smooth(r, z, slope(rim));
  double dz_dr = 0.0, d2z_dr2 = 0.0;
  RadialSlopes(smooth.Evaluate(0.05 * 0.05), 0.05, &dz_dr, &d2z_dr2);
  EXPECT_GT(std::abs(dz_dr - slope(0.05)), 1e-3);
}

TEST(TabulatedProfile, RejectsBadTables) {
  EXPECT_THROW(ProfileSpline({0.0, 1.0, 1.0, 2.0}, {0, 1, 1, 2}), std::invalid_argument);  // r not increasing
  EXPECT_THROW(ProfileSpline({0.5, 1.0, 1.5, 2.0}, {0, 1, 1, 2}), std::invalid_argument);  // no vertex row
  EXPECT_THROW(ProfileSpline({0.0, 1.0}, {0, 1}), std::invalid_argument);                  // too few rows
  const std::string path = testing::PrivateTempDir() + "/bad_profile.csv";
  std::ofstream(path) << "r,z\n0,0\n1,0.1\nabc,0.2\n";
  try {
    LoadProfileTable(path);
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find(path + ":4: column 1"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace omnical

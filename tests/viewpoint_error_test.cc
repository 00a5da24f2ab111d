// The seed's Sec. 4.2 (Eq. 23, Fig. 15): the angle error of a central virtual projector.
#include <gtest/gtest.h>

#include <cmath>

#include "correction/parallax_map.h"
#include "correction/viewpoint_error.h"
#include "test_sensors.h"
#include "model/io/sensor_yaml.h"

namespace omnical {
namespace {

std::vector<FieldSample> ShippedField(const std::string& name) {
  return AnalyzeField(LoadSensorYaml(testing::SourceDir() + "/datasets-synthetic/sensors/" + name + ".yaml"), 540,
                      5.0 * testing::kRimMm);
}

// Fig. 15 (spherical mirror, 2N = 1000 px, best V0): max |error| 0.91 px at n = 40 and
// 4.75 px at n = 7 (SEED-NOTES; the paper's own plot reads about +-1 and +-5 px).
TEST(ViewpointError, ReproducesFigure15) {
  const std::vector<FieldSample> field = ShippedField("ohte-sph");
  for (const auto& [n, expected, tolerance] : {std::tuple{40.0, 0.91, 0.05}, std::tuple{7.0, 4.75, 0.2}}) {
    const double distance = n * testing::kRimMm;
    const ParallaxCurve curve = ComputeParallaxCurve(field, distance, BestViewpointMm(field, distance));
    EXPECT_NEAR(curve.max_abs_error_px, expected, tolerance) << "n = " << n;
  }
}

// The exact geometry and Eq. 23 (with the signs the geometry fixes) agree everywhere,
// for V0 on either side of each viewpoint.
TEST(ViewpointError, ExactGeometryMatchesEquation23) {
  for (const FieldSample& f : ShippedField("ohte-sph")) {
    for (double v0 : {-20.0, 5.0, 11.5, 30.0}) {
      for (double distance : {7.0 * testing::kRimMm, 1000.0}) {
        EXPECT_NEAR(ViewpointAngleErrorRad(f.ray, distance, v0), ViewpointAngleErrorEq23Rad(f.ray, distance, v0), 1e-12);
      }
    }
  }
}

// The best V0 is the minimax: moving it either way makes the worst error larger.
TEST(ViewpointError, BestViewpointIsTheMinimax) {
  const std::vector<FieldSample> field = ShippedField("ohte-sph");
  const double distance = 7.0 * testing::kRimMm;
  const double v0 = BestViewpointMm(field, distance);
  const double worst = ComputeParallaxCurve(field, distance, v0).max_abs_error_px;
  for (double offset : {-1.0, -0.01, 0.01, 1.0})
    EXPECT_GT(ComputeParallaxCurve(field, distance, v0 + offset).max_abs_error_px, worst) << offset;
}

// A single-viewpoint mirror has no such error, and far objects have none either.
TEST(ViewpointError, VanishesForSingleViewpointAndFarObjects) {
  const std::vector<FieldSample> svp = ShippedField("ohte-svp");
  const double distance = 7.0 * testing::kRimMm;
  EXPECT_LT(ComputeParallaxCurve(svp, distance, BestViewpointMm(svp, distance)).max_abs_error_px, 1e-6);
  const std::vector<FieldSample> sph = ShippedField("ohte-sph");
  EXPECT_LT(ComputeParallaxCurve(sph, 1e9, BestViewpointMm(sph, 1e9)).max_abs_error_px, 1e-5);
}

// The exact per-pixel map agrees with the linearised curve (epsilon x dh/dOmega) where
// epsilon is small (n = 40: 0.65 deg; the curve's linearisation error is O(epsilon) of
// the value, ~1%), is zero for the single-viewpoint mirror, and sees the misalignment.
TEST(ParallaxMap, MatchesTheCurveAndSeesMisalignment) {
  const std::string dir = testing::SourceDir() + "/datasets-synthetic/sensors/";
  const double distance = 40.0 * testing::kRimMm;
  const Sensor sph = LoadSensorYaml(dir + "ohte-sph.yaml");
  const std::vector<FieldSample> field = AnalyzeField(sph, 540, distance);
  const double v0 = BestViewpointMm(field, distance);
  const double curve = ComputeParallaxCurve(field, distance, v0).max_abs_error_px;
  const ParallaxMap aligned = ComputeParallaxMap(sph, distance, v0, 2);
  EXPECT_NEAR(aligned.max_abs_error_px, curve, 0.02 * curve);
  long seen = 0;
  for (float e : aligned.error_px) seen += std::isfinite(e);
  EXPECT_GT(seen, 0.75 * 1000 * 1000);  // the image circle of radius 500 px: pi / 4 of the image

  const Sensor svp = LoadSensorYaml(dir + "ohte-svp.yaml");
  const std::vector<FieldSample> svp_field = AnalyzeField(svp, 540, distance);
  EXPECT_LT(ComputeParallaxMap(svp, 7.0 * testing::kRimMm, BestViewpointMm(svp_field, distance), 2).max_abs_error_px,
            1e-4);

  const Sensor tilted = LoadSensorYaml(dir + "ohte-sph-misaligned.yaml");
  EXPECT_GT(ComputeParallaxMap(tilted, distance, v0, 2).max_abs_error_px, 1.01 * aligned.max_abs_error_px);
}

}  // namespace
}  // namespace omnical

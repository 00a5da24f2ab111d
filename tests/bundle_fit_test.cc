// The bundle fit on exact observations (ground-truth corners projected by the model, no
// image): from a guess off by 5% in m, 3% in focal length, 10 px in the principal point,
// 2 deg of tilt and 2 mm of decenter, it must return every parameter to 1e-6 relative with
// RMS < 1e-6 px. This isolates the optimiser (and the Jet derivatives it runs on).
#include <gtest/gtest.h>

#include <cmath>

#include "calib/bundle_fit.h"
#include "correction/renderer.h"
#include "test_sensors.h"

namespace omnical {
namespace {

struct Truth {
  Sensor sensor;
  CalibrationTarget target;
  DetectionSet detections;
};

// Visible corners of the misaligned near scene's 8 views, projected by `sensor`.
Truth ExactObservations(const Sensor& sensor) {
  const Scene scene = LoadSceneYaml(testing::SourceDir() + "/datasets-synthetic/scenes/ohte-sph-misaligned-near.yaml");
  DetectionSet set;
  set.image_width_px = sensor.image_width_px();
  set.image_height_px = sensor.image_height_px();
  for (const SceneView& view : scene.views) {
    ImageDetections image;
    image.image = view.name;
    for (const TargetTruth& t : GroundTruth(sensor, view))
      for (const CornerTruth& c : t.corners)
        if (c.visible) image.corners.push_back({c.id, c.pixel});
    set.images.push_back(image);
  }
  return {sensor, *scene.views[0].targets[0].target, set};
}

Sensor Perturbed(const Sensor& truth) {
  SensorModel model = truth.model();
  std::visit(
      [](auto& m) {
        m.pose.m_mm *= 1.05;
        if constexpr (!std::decay_t<decltype(m)>::kOrthographic) {
          m.lens.fx_px *= 1.03;
          m.lens.fy_px *= 1.03;
        }
        m.lens.cx_px += 10.0;
        m.lens.cy_px -= 10.0;
        m.pose.tilt_x_rad += 2.0 * M_PI / 180.0;
        m.pose.decenter_x_mm += 2.0;
      },
      model);
  return Sensor(model);
}

void ExpectRecovered(const Truth& truth, const FitResult& fit) {
  ASSERT_TRUE(fit.sensor.has_value());
  EXPECT_TRUE(fit.converged) << fit.solver_report;
  EXPECT_LT(fit.rms_px, 1e-6) << fit.solver_report;
  EXPECT_EQ(fit.dropped, 0);
  // Compare every observable parameter with the truth, by name.
  const std::vector<ParameterEstimate> expected = SensorParameters(truth.sensor);
  ASSERT_EQ(expected.size(), fit.parameters.size());
  for (size_t k = 0; k < expected.size(); ++k) {
    if (fit.parameters[k].fixed) continue;  // a gauge the defaults fix (checked by the caller)
    // 1e-6 relative; parameters that are 0 (k1, k2, a zero tilt) to 1e-6 absolute in
    // their units (px, mm, deg, dimensionless).
    const double tolerance = 1e-6 * std::max(std::abs(expected[k].value), 1.0);
    EXPECT_NEAR(fit.parameters[k].value, expected[k].value, tolerance) << fit.parameters[k].name;
  }
}

TEST(BundleFit, RecoversTheMisalignedSphereFromExactObservations) {
  const Truth truth = ExactObservations(LoadSensorYaml(testing::SourceDir() + "/datasets-synthetic/sensors/ohte-sph-misaligned.yaml"));
  const Sensor guess = Perturbed(truth.sensor);
  std::vector<TargetPose> poses(truth.detections.images.size());
  for (size_t v = 0; v < poses.size(); ++v)
    ASSERT_TRUE(InitialTargetPose(guess, truth.target, truth.detections.images[v], &poses[v])) << v;
  const FitResult fit = FitSensor(guess, truth.target, truth.detections, poses, FitOptions::DefaultsFor(guess));
  // The sphere's tilt is its gauge (held at the guess, 2 deg off); everything else, and
  // the sphere's centre that tilt, decenter and m describe together, comes back exactly.
  for (const ParameterEstimate& p : fit.parameters) EXPECT_EQ(p.fixed, p.name.rfind("tilt", 0) == 0) << p.name;
  auto centre = [](const Sensor& sensor) {
    const auto& m = std::get<Catadioptric<double, SphereProfile, PinholeLens>>(sensor.model());
    return Eigen::Vector3d(m.pose.CameraFromMirrorRotation() * Eigen::Vector3d(0, 0, m.mirror.radius_of_curvature_mm) +
                           m.pose.CameraFromMirrorTranslation());
  };
  ASSERT_TRUE(fit.sensor.has_value());
  EXPECT_LT((centre(*fit.sensor) - centre(truth.sensor)).norm(), 1e-6 * 230.0);  // 1e-6 of its distance
  FitResult observable = fit;
  for (ParameterEstimate& p : observable.parameters)
    if (p.name == "m_mm" || p.name.rfind("decenter", 0) == 0) p.fixed = true;  // part of the centre, checked above
  ExpectRecovered(truth, observable);
  EXPECT_GT(fit.observations, 500);
}

TEST(BundleFit, RecoversAMisalignedPolynomialMirrorFromExactObservations) {
  SensorModel model = LoadSensorYaml(testing::SourceDir() + "/datasets-synthetic/sensors/ohte-edi.yaml").model();
  auto& edi = std::get<Catadioptric<double, EvenPolynomialProfile, PinholeLens>>(model);
  edi.pose.tilt_x_rad = 0.8 * M_PI / 180.0;
  edi.pose.tilt_y_rad = 0.6 * M_PI / 180.0;
  edi.pose.decenter_x_mm = 0.48;
  edi.pose.decenter_y_mm = -0.64;
  edi.image_width_px = edi.image_height_px = 1040;
  edi.lens.cx_px = edi.lens.cy_px = 519.5;
  const Truth truth = ExactObservations(Sensor(model));
  const Sensor guess = Perturbed(truth.sensor);
  std::vector<TargetPose> poses(truth.detections.images.size());
  for (size_t v = 0; v < poses.size(); ++v)
    ASSERT_TRUE(InitialTargetPose(guess, truth.target, truth.detections.images[v], &poses[v])) << v;
  ExpectRecovered(truth, FitSensor(guess, truth.target, truth.detections, poses, FitOptions::DefaultsFor(guess)));
}

TEST(FitOptions, RejectsUnknownBlocks) {
  FitOptions options;
  options.fixed = {"lens", "focal"};
  EXPECT_NE(options.Check().find("unknown block 'focal'"), std::string::npos);
  options.fixed = {"lens", "m"};
  EXPECT_EQ(options.Check(), "");
}

}  // namespace
}  // namespace omnical

// One harness, every model (basalt test_camera style): every profile x lens, aligned and
// with tilt 2 deg + decenter 1 mm, through round trips over the whole image, invalid
// regions and single-viewpoint geometry.
#include <gtest/gtest.h>

#include <cmath>

#include "model/sensor.h"
#include "test_sensors.h"

namespace omnical {
namespace {

using testing::AllTestSensors;
using testing::kRimMm;

using EveryModel = testing::EveryTestSensor;
using testing::TestSensorName;

// Projection after unprojection returns the pixel to < 1e-6 px over the whole image, for
// points from 1e-3 (0.04 mm from the mirror) to 1000 rim radii along each ray. The solver's own tolerance is
// ~1e-10 px, so 1e-6 leaves room only for genuine failures (wrong root, bad seed).
TEST_P(EveryModel, RoundTripsOverWholeImage) {
  const Sensor sensor(named().model);
  int pixels_seen = 0, points_checked = 0;
  double worst_px = 0.0;
  for (double v = 0.0; v < 1000.0; v += 9.0) {
    for (double u = 0.0; u < 1000.0; u += 9.0) {
      Eigen::Vector3d origin, direction;
      if (sensor.Unproject({u, v}, &origin, &direction) != ProjectionStatus::kOk) continue;
      ++pixels_seen;
      EXPECT_NEAR(direction.norm(), 1.0, 1e-12);
      for (double distance_rims : {1e-3, 1.0, 5.0, 40.0, 1000.0}) {
        Eigen::Vector2d pixel;
        const ProjectionStatus status = sensor.Project(origin + distance_rims * kRimMm * direction, &pixel);
        ASSERT_EQ(status, ProjectionStatus::kOk) << "pixel " << u << "," << v << " distance " << distance_rims;
        worst_px = std::max(worst_px, (pixel - Eigen::Vector2d(u, v)).norm());
        ++points_checked;
      }
    }
  }
  // The rim images at ~480 px: about 72% of the image sees the mirror.
  EXPECT_GT(pixels_seen, 0.65 * 112 * 112);
  EXPECT_LT(worst_px, 1e-6) << named().name << " over " << points_checked << " points";
}

// The same round trip through a mirror tilted 6 deg and decentred 3 mm, on pixels near
// the rim, where the reflection solver's iterates come closest to its outer wall and its
// early exit for points beyond the mirror (model/catadioptric.h) must not fire.
TEST_P(EveryModel, RoundTripsNearTheRimOfAStronglyTiltedMirror) {
  SensorModel model = named().model;
  std::visit(
      [](auto& m) {
        m.pose.tilt_x_rad = 6.0 * M_PI / 180.0, m.pose.tilt_y_rad = -4.0 * M_PI / 180.0;
        m.pose.decenter_x_mm = 2.0, m.pose.decenter_y_mm = -2.2;
      },
      model);
  const Sensor sensor(model);
  int points_checked = 0;
  double worst_px = 0.0;
  for (double v = 0.0; v < 1000.0; v += 3.0) {
    for (double u = 0.0; u < 1000.0; u += 3.0) {
      Eigen::Vector3d origin, direction;
      if (sensor.Unproject({u, v}, &origin, &direction) != ProjectionStatus::kOk) continue;
      // Only the outer ring of the field: pixels with a failing neighbour 6 px out.
      const Eigen::Vector2d outward = (Eigen::Vector2d(u, v) - Eigen::Vector2d(499.5, 499.5)).normalized();
      Eigen::Vector3d o, d;
      if (sensor.Unproject(Eigen::Vector2d(u, v) + 6.0 * outward, &o, &d) == ProjectionStatus::kOk) continue;
      for (double distance_rims : {1e-2, 1.0, 40.0, 1000.0}) {
        Eigen::Vector2d pixel;
        const ProjectionStatus status = sensor.Project(origin + distance_rims * kRimMm * direction, &pixel);
        ASSERT_EQ(status, ProjectionStatus::kOk) << "pixel " << u << "," << v << " distance " << distance_rims;
        worst_px = std::max(worst_px, (pixel - Eigen::Vector2d(u, v)).norm());
        ++points_checked;
      }
    }
  }
  EXPECT_GT(points_checked, 1000) << named().name;
  EXPECT_LT(worst_px, 1e-6) << named().name << " over " << points_checked << " points";
}

// Pixels outside the rim circle see no mirror; NaN and out-of-image input are reported.
TEST_P(EveryModel, InvalidRegionsReportStatus) {
  const Sensor sensor(named().model);
  Eigen::Vector3d origin, direction;
  // The image corners lie ~700 px from the centre, far beyond the ~480 px rim circle
  // even when misalignment shifts it by tens of pixels.
  for (const Eigen::Vector2d& corner : {Eigen::Vector2d(2, 2), Eigen::Vector2d(997, 2), Eigen::Vector2d(2, 997),
                                       Eigen::Vector2d(997, 997)}) {
    EXPECT_EQ(sensor.Unproject(corner, &origin, &direction), ProjectionStatus::kOutsideMirror) << corner.transpose();
  }
  EXPECT_EQ(sensor.Unproject({-3.0, 400.0}, &origin, &direction), ProjectionStatus::kOutsideImage);
  EXPECT_EQ(sensor.Unproject({NAN, 400.0}, &origin, &direction), ProjectionStatus::kInvalidInput);
  Eigen::Vector2d pixel;
  EXPECT_EQ(sensor.Project({NAN, 0.0, 0.0}, &pixel), ProjectionStatus::kInvalidInput);
  EXPECT_EQ(sensor.Project({1e31, 0.0, 0.0}, &pixel), ProjectionStatus::kInvalidInput);  // numerically infinite
  // Straight above the mirror, on its axis: hidden behind the mirror.
  EXPECT_NE(sensor.Project({0.0, 0.0, 5000.0}, &pixel), ProjectionStatus::kOk);
  // Inside the mirror body, just above the vertex.
  EXPECT_NE(sensor.Project({1.0, 1.0, 200.0 + 0.5 * kRimMm}, &pixel), ProjectionStatus::kOk);
}

// The vectorised batch path gives the scalar answers: the same status for every point
// (near, far, behind the mirror, beyond the rim, NaN) and pixels within 1e-9 px (both
// stop at the same ~1e-10 px Newton tolerance).
TEST_P(EveryModel, BatchProjectionMatchesScalar) {
  for (double body_radius_mm : {0.0, 15.0}) {  // with a camera body the batch tests occlusion itself
  SensorModel model = named().model;
  std::visit([&](auto& m) { m.camera_body_radius_mm = body_radius_mm; }, model);
  const Sensor sensor(model);
  std::vector<Eigen::Vector3d> points;
  for (double v = 1.0; v < 1000.0; v += 23.0) {
    for (double u = 1.0; u < 1000.0; u += 23.0) {
      Eigen::Vector3d origin, direction;
      if (sensor.Unproject({u, v}, &origin, &direction) != ProjectionStatus::kOk) continue;
      for (double distance_rims : {0.3, 5.0, 1e4}) points.push_back(origin + distance_rims * kRimMm * direction);
    }
  }
  const int valid = static_cast<int>(points.size());
  for (double z : {-2000.0, -300.0, 0.0, 150.0, 5000.0})
    for (double x : {-3000.0, -20.0, 0.0, 0.01, 5.0, 40.0, 2000.0}) points.emplace_back(x, 0.5 * x, z);
  points.emplace_back(NAN, 1.0, 1.0);
  Eigen::Matrix3Xd matrix(3, points.size());
  for (size_t i = 0; i < points.size(); ++i) matrix.col(i) = points[i];
  Eigen::Matrix2Xd pixels;
  std::vector<ProjectionStatus> statuses;
  sensor.ProjectBatch(matrix, &pixels, &statuses);
  int ok = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    Eigen::Vector2d pixel;
    const ProjectionStatus status = sensor.Project(points[i], &pixel);
    ASSERT_EQ(statuses[i], status) << "point " << points[i].transpose();
    if (status == ProjectionStatus::kOk) {
      EXPECT_LT((pixels.col(i) - pixel).norm(), 1e-9) << "point " << points[i].transpose();
      ++ok;
    } else {
      EXPECT_TRUE(std::isnan(pixels(0, i)));
    }
  }
  if (body_radius_mm == 0.0) {
    EXPECT_GE(ok, valid);
  }
  }
}

INSTANTIATE_TEST_SUITE_P(Models, EveryModel, ::testing::Range(0, static_cast<int>(AllTestSensors().size())),
                         TestSensorName);

// Where a ray crosses the mirror axis, for an axial sensor (camera frame).
double AxisCrossingZ(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double* miss_mm) {
  const double t = -origin.head<2>().dot(direction.head<2>()) / direction.head<2>().squaredNorm();
  const Eigen::Vector3d closest = origin + t * direction;
  *miss_mm = closest.head<2>().norm();
  return closest.z();
}

struct ViewpointSpread {
  double min_z = HUGE_VAL, max_z = -HUGE_VAL, worst_miss = 0.0;
};

ViewpointSpread MeasureViewpoints(const Sensor& sensor) {
  ViewpointSpread spread;
  for (double v = 3.0; v < 1000.0; v += 11.0) {
    for (double u = 3.0; u < 1000.0; u += 11.0) {
      Eigen::Vector3d origin, direction;
      if (sensor.Unproject({u, v}, &origin, &direction) != ProjectionStatus::kOk) continue;
      if (origin.head<2>().norm() < 0.5) continue;  // rays at the vertex barely leave the axis
      double miss = 0.0;
      const double z = AxisCrossingZ(origin, direction, &miss);
      spread.min_z = std::min(spread.min_z, z);
      spread.max_z = std::max(spread.max_z, z);
      spread.worst_miss = std::max(spread.worst_miss, miss);
    }
  }
  return spread;
}

// Found by review: with a table that ends at the rim and a strongly tilted orthographic
// lens, the 2-D solver's iterates left the table and the end cubic turned over. The
// table now continues along its end tangent; every visible point near the mirror solves.
TEST(TabulatedProfile, TiltedSolverConvergesNearTheRim) {
  const TabulatedProfile<double> sampled = testing::SampledEdiProfile();
  std::vector<double> r, z;
  for (size_t i = 0; i < sampled.spline->radius_mm().size(); ++i) {
    if (sampled.spline->radius_mm()[i] > kRimMm) break;
    r.push_back(sampled.spline->radius_mm()[i]);
    z.push_back(sampled.spline->sag_mm()[i]);
  }
  TabulatedProfile<double> to_rim;
  to_rim.spline = std::make_shared<const ProfileSpline>(r, z);
  for (double tilt_deg : {5.0, 10.0}) {
    auto model = testing::MakeModel<TabulatedProfile, OrthographicLens>(to_rim, 150.0, false);
    model.rim_radius_mm = r.back();
    model.pose.tilt_x_rad = tilt_deg * M_PI / 180.0;
    const Sensor sensor(model);
    int checked = 0;
    for (double v = 0.0; v < 1000.0; v += 7.0) {
      for (double u = 0.0; u < 1000.0; u += 7.0) {
        Eigen::Vector3d origin, direction;
        if (sensor.Unproject({u, v}, &origin, &direction) != ProjectionStatus::kOk) continue;
        Eigen::Vector2d pixel;
        ASSERT_EQ(sensor.Project(origin + 0.1 * direction, &pixel), ProjectionStatus::kOk) << u << "," << v;
        EXPECT_LT((pixel - Eigen::Vector2d(u, v)).norm(), 1e-6);
        ++checked;
      }
    }
    EXPECT_GT(checked, 10000);
  }
}

// A hyperboloid with the pinhole at its outer focus images through its inner focus.
TEST(SingleViewpoint, HyperboloidWithLensAtFocusHasOneViewpoint) {
  const double a = 0.7407 * kRimMm, b = 1.698 * kRimMm, c = std::hypot(a, b);
  Catadioptric<double, HyperboloidProfile, PinholeLens> model =
      testing::MakeModel<HyperboloidProfile, PinholeLens>({a, b}, b + c, false);
  const ViewpointSpread spread = MeasureViewpoints(Sensor(model));
  EXPECT_LT(spread.max_z - spread.min_z, 1e-9);
  EXPECT_LT(spread.worst_miss, 1e-9);
  // The inner focus, -B + c in the mirror frame, is 2c from the lens.
  EXPECT_NEAR(spread.min_z, 2.0 * c, 1e-9);
}

// A paraboloid seen through an orthographic lens images through its focus.
TEST(SingleViewpoint, ParaboloidWithOrthographicLensHasOneViewpoint) {
  const double focal = 0.5 * kRimMm, m = 150.0;
  const auto model = testing::MakeModel<ParaboloidProfile, OrthographicLens>({focal}, m, false);
  const ViewpointSpread spread = MeasureViewpoints(Sensor(model));
  EXPECT_LT(spread.max_z - spread.min_z, 1e-9);
  EXPECT_NEAR(spread.min_z, m + focal, 1e-9);
}

// The sphere is the seed's worst case: its viewpoints spread over millimetres.
TEST(SingleViewpoint, SphereViewpointsSpread) {
  const auto model = testing::MakeModel<SphereProfile, PinholeLens>({1.138 * kRimMm}, 4.110 * kRimMm, false);
  const ViewpointSpread spread = MeasureViewpoints(Sensor(model));
  EXPECT_GT(spread.max_z - spread.min_z, 1.0);
}

// The camera body hides the points behind it and the pixels that see its reflection.
TEST(CameraBody, OccludesPointsBehindItAndItsOwnReflection) {
  auto model = testing::MakeModel<SphereProfile, PinholeLens>({1.138 * kRimMm}, 4.110 * kRimMm, false);
  model.camera_body_radius_mm = 15.0;
  const Sensor sensor(model);
  Eigen::Vector2d pixel;
  EXPECT_EQ(sensor.Project({3.0, 2.0, -400.0}, &pixel), ProjectionStatus::kOccludedByCamera);
  Eigen::Vector3d origin, direction;
  EXPECT_EQ(sensor.Unproject({501.0, 499.5}, &origin, &direction), ProjectionStatus::kOccludedByCamera);
  // Far to the side the body is no obstacle.
  EXPECT_EQ(sensor.Project({1000.0, 0.0, -100.0}, &pixel), ProjectionStatus::kOk);
}

// Looking up past the rim (Omega > 135 deg for the seed's mirrors) sees nothing.
TEST(Field, PointsBeyondTheRimAreOutsideTheMirror) {
  const auto model = testing::MakeModel<SphereProfile, PinholeLens>({1.138 * kRimMm}, 4.110 * kRimMm, false);
  const Sensor sensor(model);
  Eigen::Vector2d pixel;
  // 170 deg from the -z axis: almost straight up beside the mirror.
  const double omega = 170.0 * M_PI / 180.0;
  const Eigen::Vector3d point(1000.0 * std::sin(omega), 0.0, 4.110 * kRimMm - 1000.0 * std::cos(omega));
  EXPECT_EQ(sensor.Project(point, &pixel), ProjectionStatus::kOutsideMirror);
}

}  // namespace
}  // namespace omnical

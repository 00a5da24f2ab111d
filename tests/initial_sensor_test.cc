// Starting sensors: from the rim circle alone (the rim's ray at the requested angle, the
// principal point at the circle's centre) and a guess converted to another mirror family
// (seeing the scene as the guess does).
#include <gtest/gtest.h>

#include <cmath>

#include "calib/initial_sensor.h"
#include "model/input_error.h"
#include "test_sensors.h"
#include "model/io/sensor_yaml.h"

namespace omnical {
namespace {

double OmegaDeg(const Sensor& sensor, const Eigen::Vector2d& pixel) {
  Eigen::Vector3d origin, direction;
  EXPECT_EQ(sensor.Unproject(pixel, &origin, &direction), ProjectionStatus::kOk);
  const Eigen::Vector3d axis = sensor.cache().camera_from_mirror_rotation.col(2);  // mirror +z in the camera
  return std::acos(std::clamp(-direction.normalized().dot(axis), -1.0, 1.0)) * 180.0 / M_PI;
}

// The closed forms put the rim's ray at the requested Omega (0.5 deg: the pixel probed sits
// 0.1% inside the rim) and the axis's ray straight back (Omega 0 at the centre).
TEST(SensorFromRimCircle, PutsTheRimRayWhereAsked) {
  RimCircle rim;
  rim.centre_px = Eigen::Vector2d(641.0, 521.5);
  rim.radius_px = 352.0;
  // Through a pinhole (a perspective camera in front of the mirror) the rim circle is the
  // nominal rim's image, the mirror reaching beyond it.
  for (const std::string lens : {"orthographic", "pinhole"})
    for (const std::string profile : {"paraboloid", "polynomial", "sphere", "even_asphere"})
      for (double field_deg : {95.0, 105.0, 120.0}) {
        const Sensor sensor = SensorFromRimCircle(rim, 1280, 1024, profile, field_deg, lens);
        EXPECT_STREQ(sensor.profile_name(), profile.c_str());
        EXPECT_STREQ(sensor.lens_name(), lens.c_str());
        EXPECT_NEAR(OmegaDeg(sensor, rim.centre_px + Eigen::Vector2d(0.999 * rim.radius_px, 0.0)), field_deg, 0.5)
            << profile << " " << lens;
        EXPECT_NEAR(OmegaDeg(sensor, rim.centre_px + Eigen::Vector2d(0.0, -0.999 * rim.radius_px)), field_deg, 0.5)
            << profile << " " << lens;
        EXPECT_LT(OmegaDeg(sensor, rim.centre_px + Eigen::Vector2d(0.5, 0.0)), 1.0) << profile << " " << lens;
      }
}

TEST(SensorFromRimCircle, RefusesWhatTheRimCannotStart) {
  RimCircle rim;
  rim.centre_px = Eigen::Vector2d(640.0, 512.0);
  rim.radius_px = 350.0;
  EXPECT_THROW(SensorFromRimCircle(rim, 1280, 1024, "hyperboloid"), InputError);
  EXPECT_THROW(SensorFromRimCircle(rim, 1280, 1024, "paraboloid", 179.0), InputError);
  EXPECT_THROW(SensorFromRimCircle(rim, 1280, 1024, "polynomial", 105.0, "fisheye"), InputError);
  // A pinhole sees the rim 12 deg off its axis: a rim ray at 11 deg would need a concave rim.
  EXPECT_THROW(SensorFromRimCircle(rim, 1280, 1024, "polynomial", 11.0, "pinhole"), InputError);
  rim.radius_px = 0.0;
  EXPECT_THROW(SensorFromRimCircle(rim, 1280, 1024, "polynomial"), InputError);
}

// Shipped designs in another family: the same scene points must land near the same
// pixels, as near as the families allow. A sphere's slope runs away towards its rim (r/A
// = 0.88 there), which three terms in r^2 follow to a few px and a one-parameter
// paraboloid, or a hyperboloid (whose slope flattens), only on average; a hyperboloid is
// smooth in r^2 and a polynomial follows it to a few px. Bounds ~2x the measured worst pixel
// distance (SPH: polynomial 5.9, paraboloid 48, hyperboloid 55; SVP: polynomial 2.5 px):
// a start for the fit, which must then converge (tests/bundle_fit_test).
TEST(ConvertProfile, SeesTheSceneAsTheGuessDoes) {
  struct Case {
    std::string sensor, profile;
    double bound_px;
  };
  for (const Case& c : std::vector<Case>{{"ohte-sph", "polynomial", 12.0},
                                         {"ohte-sph", "paraboloid", 100.0},
                                         {"ohte-sph", "hyperboloid", 110.0},
                                         {"ohte-svp", "polynomial", 5.0},
                                         // The even asphere holds the sphere (k = 0) and the
                                         // hyperboloid exactly: the fit from its paraboloid
                                         // start must find them (1e-3 px: the sag fit's
                                         // tolerance, 1e-14, not the families).
                                         {"ohte-sph", "even_asphere", 1e-3},
                                         {"ohte-svp", "even_asphere", 1e-3},
                                         {"ohte-edi", "even_asphere", 12.0}}) {
    const Sensor guess = LoadSensorYaml(testing::SourceDir() + "/datasets-synthetic/sensors/" + c.sensor + ".yaml");
    const Sensor converted = ConvertProfile(guess, c.profile);
    EXPECT_STREQ(converted.profile_name(), c.profile.c_str());
    double worst = 0.0;
    int compared = 0;
    for (double omega_deg = 20.0; omega_deg <= 130.0; omega_deg += 5.0) {
      const double omega = omega_deg * M_PI / 180.0;
      // A point 2 m from the mirror's vertex (the mirror's +z is the camera's +z here).
      const Eigen::Vector3d point(2000.0 * std::sin(omega), 0.0, guess.cache().camera_from_mirror_translation.z() - 2000.0 * std::cos(omega));
      Eigen::Vector2d a, b;
      if (guess.Project(point, &a) != ProjectionStatus::kOk || converted.Project(point, &b) != ProjectionStatus::kOk) continue;
      worst = std::max(worst, (a - b).norm());
      ++compared;
    }
    EXPECT_GT(compared, 15) << c.sensor << " as " << c.profile;
    EXPECT_LT(worst, c.bound_px) << c.sensor << " as " << c.profile;
    RecordProperty(c.sensor + "_as_" + c.profile + "_worst_px", std::to_string(worst));
  }
  const Sensor sph = LoadSensorYaml(testing::SourceDir() + "/datasets-synthetic/sensors/ohte-sph.yaml");
  EXPECT_EQ(ConvertProfile(sph, "sphere").model().index(), sph.model().index());
  EXPECT_THROW(ConvertProfile(sph, "cone"), InputError);
}

}  // namespace
}  // namespace omnical

// The mirror's rim circle found in images: against the rim's true projection on renders,
// across the ten real images, and nothing on images with no mirror.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>

#include "calib/bundle_fit.h"
#include "calib/initial_sensor.h"
#include "calib/rim_circle.h"
#include "model/io/codecs/image_codecs.h"
#include "test_sensors.h"
#include "model/io/sensor_yaml.h"

namespace omnical {
namespace {

// Radius (px) where pixels along the row through (cx, cy) stop seeing the mirror: bisection
// on the unprojection status, to 1e-3 px.
double TrueRimRadiusPx(const Sensor& sensor, const Eigen::Vector2d& centre) {
  double inside = 1.0, outside = 0.5 * sensor.image_width_px() + 50.0;
  Eigen::Vector3d origin, direction;
  for (int i = 0; i < 40; ++i) {
    const double mid = 0.5 * (inside + outside);
    const bool sees = sensor.Unproject(centre + Eigen::Vector2d(mid, 0.0), &origin, &direction) == ProjectionStatus::kOk;
    (sees ? inside : outside) = mid;
  }
  return inside;
}

// The aligned SPH sensor: the rim is a circle about the principal point. Tolerances: the
// edge points scatter by ~1.3 px (blur, 1 px steps) over ~600 rays, so the fitted centre and
// radius are good to a few tenths of a pixel; 0.5 px centre, 1 px radius (the rendered disc
// ends in a partial pixel, antialiased).
TEST(RimCircle, FindsTheRimOfARenderedMirror) {
  for (const std::string view : {"ohte-sph-near/near000.png", "ohte-sph-far/far002.png", "ohte-edi-near/near001.png"}) {
    const std::string set = testing::SourceDir() + "/datasets-synthetic/rendered/" + view.substr(0, view.find('/'));
    const Sensor sensor = LoadSensorYaml(set + "/sensor.yaml");
    const cv::Mat grey = omnical::LoadImageFile(testing::SourceDir() + "/datasets-synthetic/rendered/" + view, cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(grey.empty()) << view;
    const auto circle = DetectRimCircle(grey);
    ASSERT_TRUE(circle) << view;
    const Eigen::Vector2d principal(0.5 * (sensor.image_width_px() - 1), 0.5 * (sensor.image_height_px() - 1));
    EXPECT_LT((circle->centre_px - principal).norm(), 0.5) << view;
    EXPECT_NEAR(circle->radius_px, TrueRimRadiusPx(sensor, principal), 1.0) << view;
    EXPECT_GT(circle->inlier_fraction, 0.5) << view;
  }
}

// No mirror: a uniform frame, and uniform noise, give nothing.
TEST(RimCircle, FindsNothingWithoutAMirror) {
  EXPECT_FALSE(DetectRimCircle(cv::Mat(480, 640, CV_8U, cv::Scalar(128))));
  cv::Mat noise(480, 640, CV_8U);
  cv::randu(noise, 0, 255);
  EXPECT_FALSE(DetectRimCircle(noise));
  EXPECT_FALSE(DetectRimCircle(cv::Mat()));
}

// The ten real images: the rim does not move on the sensor, so every image's circle must
// agree with the median to the edge scatter (2 px).
TEST(RimCircle, AgreesAcrossTheRealImages) {
  const std::string data = testing::SourceDir() + "/../shared/real-data/mei-parabolic";
  if (!std::filesystem::exists(data)) GTEST_SKIP() << data << " is absent";
  std::vector<RimCircle> circles;
  for (int k = 1; k <= 10; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "/img_para_%03d.pgm", k);
    const auto circle = DetectRimCircle(omnical::LoadImageFile(data + name, cv::IMREAD_GRAYSCALE));
    ASSERT_TRUE(circle) << name;
    circles.push_back(*circle);
  }
  const auto median = MedianRimCircle(circles);
  ASSERT_TRUE(median);
  for (const RimCircle& c : circles) {
    EXPECT_LT((c.centre_px - median->centre_px).norm(), 2.0);
    EXPECT_NEAR(c.radius_px, median->radius_px, 2.0);
  }
}

// A sensor whose rim radius is off (a fit keeps the design's) gets the rim the image shows:
// on the realistic render (misaligned sphere, the rim 10-16 px off the image centre) a
// sensor with its rim 4 % too wide or too narrow (~20 px at the rim) comes back to the
// truth's 43.9 mm within 0.1 mm (~1 px there: the circle sits 0.3-0.7 px inside the true
// rim, the blur's midpoint, and the misaligned rim is not quite a circle). A circle at half
// the radius would move the rim by far more than 10 %: nothing; nor one 30 % wider (most of
// it beyond the image).
TEST(RimCircle, MovesASensorsRimOntoTheImages) {
  const std::string set = testing::SourceDir() + "/datasets-synthetic/rendered/realistic-aprilgrid";
  const Sensor truth = LoadSensorYaml(set + "/sensor.yaml");
  const auto circle = DetectRimCircle(omnical::LoadImageFile(set + "/rim0.jpg", cv::IMREAD_GRAYSCALE));
  ASSERT_TRUE(circle);
  for (const double factor : {0.96, 1.04}) {
    const Sensor off = SensorWithWiderRim(truth, factor);
    ASSERT_GT(std::abs(off.rim_radius_mm() - truth.rim_radius_mm()), 1.5);
    const auto moved = SensorWithImageRim(off, *circle);
    ASSERT_TRUE(moved) << factor;
    EXPECT_NEAR(moved->rim_radius_mm(), truth.rim_radius_mm(), 0.1) << factor;
  }
  // Refused with the reason calibrate's warning (image_rim_not_used) passes on: the circle,
  // and the radius it would give the mirror where it meets the mirror.
  RimCircle half = *circle;
  half.radius_px *= 0.5;
  std::string why;
  EXPECT_FALSE(SensorWithImageRim(truth, half, &why));
  char radius[32];
  std::snprintf(radius, sizeof radius, "radius %.1f px", half.radius_px);  // as the message prints it
  EXPECT_NE(why.find(radius), std::string::npos) << why;
  EXPECT_NE(why.find("whose rim is 43.9"), std::string::npos) << why;
  RimCircle beyond = *circle;
  beyond.radius_px *= 1.3;
  why.clear();
  EXPECT_FALSE(SensorWithImageRim(truth, beyond, &why));
  EXPECT_NE(why.find("lies in the image at under half its points"), std::string::npos) << why;
}

// A fit without a design has a rim that only encloses its corners. Where no board reached
// the rim, the images' circle lies beyond it: a conic (here the render's sphere) may follow
// it up to 25 % out, its curvature continuing as the mirror's does; a mirror with free-form
// terms only 10 %, since past its corners those terms are extrapolated
// (calib/profile_choice.h: a polynomial widened 19 % lost its refit). A design's rim is the
// mirror's: 10 % for any. Inwards 10 % for all: corners beyond a rim are no rim's.
TEST(RimCircle, LetsAConicsRimGrowFurtherThanAFreeFormOnes) {
  const std::string set = testing::SourceDir() + "/datasets-synthetic/rendered/realistic-aprilgrid";
  const Sensor truth = LoadSensorYaml(set + "/sensor.yaml");
  ASSERT_EQ(std::string(truth.profile_name()), "sphere");
  const auto circle = DetectRimCircle(omnical::LoadImageFile(set + "/rim0.jpg", cv::IMREAD_GRAYSCALE));
  ASSERT_TRUE(circle);
  const Sensor free_form = ConvertProfile(truth, "polynomial");
  for (const double growth : {1.15, 1.2}) {
    const Sensor conic_inside = SensorWithWiderRim(truth, 1.0 / growth);
    const auto moved = SensorWithImageRim(conic_inside, *circle, nullptr, /*rim_from_corners=*/true);
    ASSERT_TRUE(moved) << growth;
    EXPECT_NEAR(moved->rim_radius_mm(), truth.rim_radius_mm(), 0.1) << growth;
    std::string why;
    EXPECT_FALSE(SensorWithImageRim(SensorWithWiderRim(free_form, 1.0 / growth), *circle, &why, true)) << growth;
    EXPECT_NE(why.find("over 10 % beyond it (free-form terms"), std::string::npos) << why;
    why.clear();  // the same conic as a design: its rim is the mirror's
    EXPECT_FALSE(SensorWithImageRim(conic_inside, *circle, &why)) << growth;
    EXPECT_NE(why.find("over 10 % beyond the design's rim"), std::string::npos) << why;
  }
  std::string why;  // 28 %: beyond a conic's 25 %
  EXPECT_FALSE(SensorWithImageRim(SensorWithWiderRim(truth, 1.0 / 1.28), *circle, &why, true));
  EXPECT_NE(why.find("over 25 % beyond it"), std::string::npos) << why;
  why.clear();  // inwards: 10 % for a conic too
  EXPECT_FALSE(SensorWithImageRim(SensorWithWiderRim(truth, 1.15), *circle, &why, true));
  EXPECT_NE(why.find("over 10 % inside it"), std::string::npos) << why;
}

}  // namespace
}  // namespace omnical

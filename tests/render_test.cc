// The renderer: its ray interpolation is within its stated bound, rendered corners sit
// where the ground truth says (checked with an independent detector, OpenCV's
// cornerSubPix), it is deterministic, and the ground truth's visibility is right.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <random>

#include "calib/synthetic/renderer.h"
#include "test_sensors.h"
#include "model/io/sensor_yaml.h"

namespace omnical {
namespace {

Sensor ShippedSensor(const std::string& name) {
  return LoadSensorYaml(testing::SourceDir() + "/datasets-synthetic/sensors/" + name + ".yaml");
}

// The bilinear ray interpolation is within 0.01 px everywhere (the bound the
// renderer's header states): a point 5 rim radii along an interpolated ray projects back
// to the sample it came from.
TEST(PixelRayGrid, InterpolationErrorIsBelowAHundredthOfAPixel) {
  for (const char* name : {"ohte-sph", "ohte-sph-misaligned"}) {
    const Sensor sensor = ShippedSensor(name);
    const PixelRayGrid rays(sensor, 2);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> coordinate(0.0, sensor.image_width_px() - 1.0);
    double worst = 0.0;
    int checked = 0;
    while (checked < 20000) {
      const Eigen::Vector2d sample(coordinate(rng), coordinate(rng));
      Eigen::Vector3d origin, direction;
      if (rays.Ray(sample.x(), sample.y(), &origin, &direction) != ProjectionStatus::kOk) continue;
      Eigen::Vector2d pixel;
      ASSERT_EQ(sensor.Project(origin + 5.0 * sensor.rim_radius_mm() * direction, &pixel), ProjectionStatus::kOk);
      worst = std::max(worst, (pixel - sample).norm());
      ++checked;
    }
    EXPECT_LT(worst, 0.01) << name;
    RecordProperty(std::string("worst_interpolation_px_") + name, std::to_string(worst));
  }
}

// A checkerboard rendered noise-free at 16 samples per pixel at elevations across the
// whole field; cornerSubPix, started up to 3 px off the ground truth, must land within
// RMS 0.1 px of it at every elevation. Squares of 30 mm at 200 mm stay >= 15 px even where
// the sphere compresses the image most (dh/dOmega 1.4-2 px/deg near the rim), so the
// 11 x 11 px window sees one corner; corners whose window reaches past the mirror's rim
// (the dark housing) are left out, as any detector would.
TEST(Renderer, CornersSitWhereTheGroundTruthSays) {
  const Sensor sensor = ShippedSensor("ohte-sph");
  const auto board = std::make_shared<const CalibrationTarget>(CalibrationTarget::Checkerboard(7, 5, 30.0, 30.0));
  const PixelRayGrid rays(sensor, 2);
  auto window_on_mirror = [&](const Eigen::Vector2d& pixel) {
    Eigen::Vector3d origin, direction;
    for (double du : {-6.0, 6.0})
      for (double dv : {-6.0, 6.0})
        if (sensor.Unproject(pixel + Eigen::Vector2d(du, dv), &origin, &direction) != ProjectionStatus::kOk) return false;
    return true;
  };
  Environment grey;
  grey.type = Environment::Type::kGrey;
  ImageFormation formation;  // 16 spp, no noise, no blur
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> offset(-3.0f, 3.0f);
  // Flat, and bent by 8 mm along x and -4 mm along y (calib/board_warp.h): the bent
  // board's corners move by pixels, and the image must follow the truth there too.
  for (const BoardWarp& warp : {BoardWarp{0.0, 0.0}, BoardWarp{8.0, -4.0}})
  for (double omega : {30.0, 55.0, 80.0, 105.0, 125.0}) {
    if (!warp.IsZero() && omega != 55.0 && omega != 105.0) continue;  // two directions suffice (test time)
    SceneView view;
    PlacedTarget placed{"board", board, "", Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), {}};
    PlaceTarget(sensor, *board, omega, 20.0, 200.0, 0.0, 0.0, 0.0, &placed.camera_from_target_rotation,
                &placed.camera_from_target_translation_mm);
    placed.surface = WarpedSurface::Of(*board, warp);
    view.targets.push_back(placed);
    const cv::Mat image = RenderView(sensor, rays, view, grey, formation, 0, 2);
    const std::vector<TargetTruth> truth = GroundTruth(sensor, view);
    if (!warp.IsZero()) {  // the bend is visible: the centre corner moves by over a pixel
      SceneView flat_view = view;
      flat_view.targets[0].surface = WarpedSurface::Of(*board, BoardWarp());
      const std::vector<TargetTruth> flat = GroundTruth(sensor, flat_view);
      double moved = 0.0;
      for (size_t k = 0; k < flat[0].corners.size(); ++k)
        if (flat[0].corners[k].visible && truth[0].corners[k].visible)
          moved = std::max(moved, (flat[0].corners[k].pixel - truth[0].corners[k].pixel).norm());
      EXPECT_GT(moved, 1.0) << "Omega " << omega;
    }
    std::vector<cv::Point2f> start, truth_px;
    for (const CornerTruth& c : truth[0].corners) {
      if (!c.visible || !window_on_mirror(c.pixel)) continue;
      truth_px.emplace_back(c.pixel.x(), c.pixel.y());
      start.emplace_back(c.pixel.x() + offset(rng), c.pixel.y() + offset(rng));
    }
    ASSERT_GE(truth_px.size(), 20u) << "Omega " << omega;
    cv::cornerSubPix(image, start, cv::Size(5, 5), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 100, 1e-4));
    double sum = 0.0;
    for (size_t i = 0; i < start.size(); ++i) {
      const double dx = start[i].x - truth_px[i].x, dy = start[i].y - truth_px[i].y;
      sum += dx * dx + dy * dy;
    }
    const double rms = std::sqrt(sum / start.size());
    EXPECT_LT(rms, 0.1) << "Omega " << omega << " deg, warp " << warp.x_mm << " mm";
    RecordProperty("rms_px_omega_" + std::to_string(static_cast<int>(omega)) + (warp.IsZero() ? "" : "_warped"),
                   std::to_string(rms));
  }
}

TEST(Renderer, IsDeterministicAndHonoursTheSeed) {
  const Scene scene = LoadSceneYaml(testing::SourceDir() + "/datasets-synthetic/scenes/ohte-sph-near.yaml");
  ImageFormation noisy = scene.formation;
  noisy.samples_per_pixel = 1;
  noisy.noise_sigma = 2.0;
  const PixelRayGrid rays(*scene.sensor, 2);
  const cv::Mat a = RenderView(*scene.sensor, rays, scene.views[0], scene.environment, noisy, 0, 2);
  const cv::Mat b = RenderView(*scene.sensor, rays, scene.views[0], scene.environment, noisy, 0, 1);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);  // same seed, any number of threads
  noisy.seed += 1;
  const cv::Mat c = RenderView(*scene.sensor, rays, scene.views[0], scene.environment, noisy, 0, 2);
  EXPECT_GT(cv::norm(a, c, cv::NORM_L1), 0.0);
}

// A board behind another is hidden; a board turned away shows no corners.
TEST(GroundTruth, HidesOccludedAndBackFacingCorners) {
  const Sensor sensor = ShippedSensor("ohte-sph");
  const auto board = std::make_shared<const CalibrationTarget>(CalibrationTarget::Checkerboard(7, 5, 28.0, 28.0));
  SceneView view;
  for (double distance : {250.0, 500.0}) {
    PlacedTarget placed{"board", board, "", Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), {}};
    PlaceTarget(sensor, *board, 80.0, 0.0, distance, 0.0, 0.0, 0.0, &placed.camera_from_target_rotation,
                &placed.camera_from_target_translation_mm);
    view.targets.push_back(placed);
  }
  std::vector<TargetTruth> truth = GroundTruth(sensor, view);
  int front = 0, back = 0;
  for (const CornerTruth& c : truth[0].corners) front += c.visible;
  for (const CornerTruth& c : truth[1].corners) back += c.visible;
  EXPECT_EQ(front, 35);
  EXPECT_EQ(back, 0);  // the far board is exactly behind the near one, and smaller in angle
  // Turn the near board around: its printed face looks away.
  view.targets.resize(1);
  PlaceTarget(sensor, *board, 80.0, 0.0, 250.0, 0.0, 180.0, 0.0, &view.targets[0].camera_from_target_rotation,
              &view.targets[0].camera_from_target_translation_mm);
  truth = GroundTruth(sensor, view);
  for (const CornerTruth& c : truth[0].corners) EXPECT_FALSE(c.visible);
}

}  // namespace
}  // namespace omnical

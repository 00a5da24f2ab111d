// The bundle fit on exact observations (ground-truth corners projected by the model, no
// image): from a guess off by 5% in m, 3% in focal length, 10 px in the principal point,
// 2 deg of tilt and 2 mm of decenter, it must return every parameter to 1e-6 relative with
// RMS < 1e-6 px. This isolates the optimiser (and the Jet derivatives it runs on).
#include <gtest/gtest.h>

#include <ceres/autodiff_cost_function.h>
#include <ceres/problem.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <random>

#include "calib/board_warp.h"
#include "calib/bundle_fit.h"
#include "calib/fit_covariance.h"
#include "calib/initial_sensor.h"
#include "calib/knot_choice.h"
#include "calib/predicted_error.h"
#include "calib/parallel_evaluation.h"
#include "calib/projection_diff.h"
#include "calib/sensor_blocks.h"
#include "calib/synthetic/renderer.h"
#include "test_sensors.h"
#include "model/io/sensor_yaml.h"

namespace omnical {
namespace {

struct Truth {
  Sensor sensor;
  CalibrationTarget target;
  DetectionSet detections;
};

// Visible corners of the views, projected by `sensor`.
Truth ObservationsOf(const Sensor& sensor, const std::vector<SceneView>& views);

// The misaligned near scene's 8 views.
Truth ExactObservations(const Sensor& sensor) {
  return ObservationsOf(sensor, LoadSceneYaml(testing::SourceDir() +
                                              "/datasets-synthetic/scenes/ohte-sph-misaligned-near.yaml").views);
}

// 16 views of the 30 mm aprilgrid at mixed distances (4-30 mirror radii) and elevations:
// with one size at one range the mirror's scale rests on a faint parallax and the
// linearised standard deviations understate a curved uncertainty; a calibration set spans
// distances, so the statistical tests use one.
std::vector<SceneView> MixedDistanceViews(const Sensor& sensor) {
  const auto board = std::make_shared<const CalibrationTarget>(
      CalibrationTarget::FromYaml(testing::SourceDir() + "/datasets-synthetic/targets/aprilgrid-6x6-30mm.yaml"));
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<SceneView> views;
  for (int k = 0; k < 16; ++k) {
    SceneView view;
    PlacedTarget placed{"board", board, "", Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), {}};
    const double distance = testing::kRimMm * 4.0 * std::pow(30.0 / 4.0, k / 15.0);
    PlaceTarget(sensor, *board, 40.0 + 80.0 * unit(rng), 360.0 * unit(rng), distance, 60.0 * unit(rng) - 30.0,
                30.0 * unit(rng) - 15.0, 30.0 * unit(rng) - 15.0, &placed.camera_from_target_rotation,
                &placed.camera_from_target_translation_mm);
    view.name = "mixed" + std::to_string(k);
    view.targets.push_back(placed);
    views.push_back(view);
  }
  return views;
}

Truth MixedDistanceObservations(const Sensor& sensor) { return ObservationsOf(sensor, MixedDistanceViews(sensor)); }

// The mixed views of a board bent by `warp` (calib/board_warp.h), projected point by
// point through the sensor (the renderer's boards are flat).
Truth WarpedObservations(const Sensor& sensor, const BoardWarp& warp) {
  const std::vector<SceneView> views = MixedDistanceViews(sensor);
  const CalibrationTarget& board = *views[0].targets[0].target;
  const std::map<int, Eigen::Vector2d> basis = BoardWarp::Basis(board);
  DetectionSet set;
  set.image_width_px = sensor.image_width_px();
  set.image_height_px = sensor.image_height_px();
  for (const SceneView& view : views) {
    const PlacedTarget& placed = view.targets[0];
    ImageDetections image;
    image.image = view.name;
    for (const TargetCorner& c : board.corners()) {
      const Eigen::Vector3d bent =
          c.point_in_target + Eigen::Vector3d(0.0, 0.0, warp.CornerOffsetMm(c.id, basis.at(c.id)));
      Eigen::Vector2d pixel;
      if (sensor.Project(placed.camera_from_target_rotation * bent + placed.camera_from_target_translation_mm, &pixel) ==
          ProjectionStatus::kOk)
        image.corners.push_back({c.id, pixel});
    }
    if (image.corners.size() >= 8) set.images.push_back(image);
  }
  return {sensor, board, set};
}

Truth ObservationsOf(const Sensor& sensor, const std::vector<SceneView>& views) {
  DetectionSet set;
  set.image_width_px = sensor.image_width_px();
  set.image_height_px = sensor.image_height_px();
  for (const SceneView& view : views) {
    ImageDetections image;
    image.image = view.name;
    for (const TargetTruth& t : GroundTruth(sensor, view))
      for (const CornerTruth& c : t.corners)
        if (c.visible) image.corners.push_back({c.id, c.pixel});
    if (image.corners.size() >= 8) set.images.push_back(image);
  }
  return {sensor, *views[0].targets[0].target, set};
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
  // The sphere's tilt is its gauge (held at the guess, 2 deg off) and p1, p2 are held by
  // default (the truth has none); everything else, and the sphere's centre that tilt,
  // decenter and m describe together, comes back exactly.
  for (const ParameterEstimate& p : fit.parameters)
    EXPECT_EQ(p.fixed, p.name.rfind("tilt", 0) == 0 || p.name == "p1" || p.name == "p2") << p.name;
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

// Corner noise of 0.5 px per axis on exact observations: the RMS (per corner) matches the
// noise, sigma sqrt(2) sqrt(1 - p / 2N), within 10%, and every parameter lands within 3 of
// its reported standard deviations of the truth, for several (fixed) seeds. This checks
// the standard deviations themselves.
// The misaligned sphere (a rigid profile whose one gauge, tilt, is fixed) with m known from
// the mechanical design; see the note inside. Under those conditions the linearised
// standard deviations describe the error. (docs/calibrate.md "What the data can observe".)
void NoisyFitHolds(bool with_outliers) {
  const Truth truth = MixedDistanceObservations(
      LoadSensorYaml(testing::SourceDir() + "/datasets-synthetic/sensors/ohte-sph-misaligned.yaml"));
  ASSERT_GE(truth.detections.images.size(), 12u);
  const std::vector<ParameterEstimate> expected = SensorParameters(truth.sensor);
  Sensor guess = Perturbed(truth.sensor);
  {  // the designed m (the guess's other errors stay)
    SensorModel m = guess.model();
    std::get<Catadioptric<double, SphereProfile, PinholeLens>>(m).pose.m_mm =
        std::get<Catadioptric<double, SphereProfile, PinholeLens>>(truth.sensor.model()).pose.m_mm;
    guess = Sensor(m);
  }
  for (unsigned seed : {1u, 2u, 3u}) {
    DetectionSet noisy = truth.detections;
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, 0.5);
    int corners = 0;
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    int outliers = 0;
    for (ImageDetections& image : noisy.images) {
      for (CornerObservation& c : image.corners) {
        c.pixel += Eigen::Vector2d(noise(rng), noise(rng));
        ++corners;
        if (with_outliers && unit(rng) < 0.05) {  // a gross error of 20-60 px in a random direction
          const double angle = 2.0 * M_PI * unit(rng), length = 20.0 + 40.0 * unit(rng);
          c.pixel += length * Eigen::Vector2d(std::cos(angle), std::sin(angle));
          ++outliers;
        }
      }
    }
    std::vector<TargetPose> poses(noisy.images.size());
    for (size_t v = 0; v < poses.size(); ++v) ASSERT_TRUE(InitialTargetPose(guess, truth.target, noisy.images[v], &poses[v]));
    FitOptions options = FitOptions::DefaultsFor(guess);
    // m from the mechanical design: with it free, fx and m form a valley (a "dolly zoom":
    // the lens sees the mirror under a small angle, so backing off while zooming in leaves
    // the image almost unchanged) that 0.5 px of noise cannot resolve: a fit started at
    // the truth drifts ~25% along it at the same RMS, which no linearised std describes.
    options.refine.m = false;
    if (!with_outliers) options.robust_loss_px = 0.0;  // Gaussian noise: plain least squares
    const FitResult fit = FitSensor(guess, truth.target, noisy, poses, options);
    ASSERT_TRUE(fit.covariance_ok) << "seed " << seed;
    ::testing::Test::RecordProperty("report_seed" + std::to_string(seed) + (with_outliers ? "_outliers" : ""), fit.solver_report);
    const int parameters = static_cast<int>(expected.size()) + 6 * static_cast<int>(poses.size());
    const int inliers = corners - (with_outliers ? fit.outliers : 0);
    const double expected_rms = 0.5 * std::sqrt(2.0) * std::sqrt(1.0 - parameters / (2.0 * inliers));
    EXPECT_NEAR(fit.rms_px, expected_rms, 0.1 * expected_rms) << "seed " << seed;
    if (with_outliers) {
      // Every injected outlier (20-60 px against a 2.5 px threshold: 5 sigma of 0.5 px; the
      // bulk's sigma leaves them out, they lie beyond 8 median-sigma) goes; of the Gaussian
      // corners a 2-D tail beyond 5 sigma, exp(-12.5) = 4e-6 of them (~0.01 here), may go
      // too: 1 allows for that (Poisson P(>= 2) < 1e-4). The threshold within 10 %, the
      // RMS's own bound above.
      EXPECT_GE(fit.outliers, outliers) << "seed " << seed;
      EXPECT_LE(fit.outliers, outliers + 1) << "seed " << seed;
      EXPECT_NEAR(fit.outlier_threshold_px, 5.0 * 0.5, 0.25) << "seed " << seed;
    }
    for (size_t k = 0; k < expected.size(); ++k) {
      if (fit.parameters[k].fixed) continue;  // a gauge, held at the guess
      EXPECT_LT(std::abs(fit.parameters[k].value - expected[k].value), 3.0 * fit.parameters[k].std)
          << "seed " << seed << " " << fit.parameters[k].name << " = " << fit.parameters[k].value << " +- "
          << fit.parameters[k].std << ", truth " << expected[k].value;
    }
  }
}

TEST(BundleFit, StandardDeviationsHoldUnderNoise) { NoisyFitHolds(false); }

// The same with 5% of the corners replaced by gross outliers (tens of px): the robust
// fit finds exactly them and the rest holds.
TEST(BundleFit, StandardDeviationsHoldWithGrossOutliers) { NoisyFitHolds(true); }

// Per-view noise weights (FitOptions::view_noise_weights) on views of two qualities: half
// the views with 0.05 px of noise per axis, half with 0.4 px (a sharp view and a blurred
// rim view of a real set differ ~5x). Each view's weight must follow its noise: weight x
// sigma the same for every view within 15 % (a view's sigma from ~100-250 corners is
// estimated to ~5 %, 3 of those). The weighted fit's parameters must lie within 3 of its
// reported std of the truth (the covariance holds with the weights), and those std must
// be under half the unweighted fit's (whose covariance scales by one pooled sigma ~0.3 px
// where most of the information comes from views at 0.05 px). Without the option no
// weights are reported. The sphere as in NoisyFitHolds, m held at the design.
TEST(BundleFit, ViewNoiseWeightsFollowEachViewsNoise) {
  const Truth truth = MixedDistanceObservations(
      LoadSensorYaml(testing::SourceDir() + "/datasets-synthetic/sensors/ohte-sph-misaligned.yaml"));
  const std::vector<ParameterEstimate> expected = SensorParameters(truth.sensor);
  Sensor guess = Perturbed(truth.sensor);
  {  // the designed m, and the true tilt: the sphere's tilt is its gauge, held, and a held
     // tilt 2 deg off moves the fitted decenter by A sin 2 deg = 1.7 mm (NoisyFitHolds'
     // 0.5 px std hide it); the guess's other errors stay
    SensorModel m = guess.model();
    auto& sphere = std::get<Catadioptric<double, SphereProfile, PinholeLens>>(m);
    const auto& true_sphere = std::get<Catadioptric<double, SphereProfile, PinholeLens>>(truth.sensor.model());
    sphere.pose.m_mm = true_sphere.pose.m_mm;
    sphere.pose.tilt_x_rad = true_sphere.pose.tilt_x_rad;
    guess = Sensor(m);
  }
  for (unsigned seed : {4u, 5u}) {
    DetectionSet noisy = truth.detections;
    std::mt19937 rng(seed);
    std::vector<double> sigma_px;
    for (size_t v = 0; v < noisy.images.size(); ++v) {
      sigma_px.push_back(v % 2 == 0 ? 0.05 : 0.4);
      std::normal_distribution<double> noise(0.0, sigma_px.back());
      for (CornerObservation& c : noisy.images[v].corners) c.pixel += Eigen::Vector2d(noise(rng), noise(rng));
    }
    std::vector<TargetPose> poses(noisy.images.size());
    for (size_t v = 0; v < poses.size(); ++v) ASSERT_TRUE(InitialTargetPose(guess, truth.target, noisy.images[v], &poses[v]));
    FitOptions options = FitOptions::DefaultsFor(guess);
    options.refine.m = false;  // the dolly-zoom valley, as in NoisyFitHolds
    options.robust_loss_px = 0.0;
    const FitResult plain = FitSensor(guess, truth.target, noisy, poses, options);
    options.view_noise_weights = true;
    const FitResult weighted = FitSensor(guess, truth.target, noisy, poses, options);
    ASSERT_TRUE(plain.covariance_ok && weighted.covariance_ok) << "seed " << seed;
    EXPECT_TRUE(plain.per_view_weight.empty());
    ASSERT_EQ(weighted.per_view_weight.size(), noisy.images.size());
    double mean = 0.0;
    for (size_t v = 0; v < sigma_px.size(); ++v) mean += weighted.per_view_weight[v] * sigma_px[v] / sigma_px.size();
    for (size_t v = 0; v < sigma_px.size(); ++v)
      EXPECT_NEAR(weighted.per_view_weight[v] * sigma_px[v], mean, 0.15 * mean)
          << "seed " << seed << " view " << v << " weight " << weighted.per_view_weight[v] << " left out '"
          << weighted.view_left_out[v] << "'";
    for (size_t k = 0; k < expected.size(); ++k) {
      if (weighted.parameters[k].fixed) continue;
      const ParameterEstimate& p = weighted.parameters[k];
      EXPECT_LT(std::abs(p.value - expected[k].value), 3.0 * p.std)
          << "seed " << seed << " " << p.name << " = " << p.value << " +- " << p.std << ", truth " << expected[k].value;
      EXPECT_LT(p.std, 0.5 * plain.parameters[k].std) << "seed " << seed << " " << p.name;
    }
  }
}

std::vector<TargetPose> StartingPoses(const Sensor& guess, const Truth& truth) {
  std::vector<TargetPose> poses(truth.detections.images.size());
  for (size_t v = 0; v < poses.size(); ++v)
    EXPECT_TRUE(InitialTargetPose(guess, truth.target, truth.detections.images[v], &poses[v])) << v;
  return poses;
}

// A start whose rim reaches past what its lens can see (a pinhole's start from the rim
// circle reaches 1.5 x past the nominal rim, and a fit may shrink the mirror: see
// FittedModel): the fitted sensor's rim is drawn in to a valid mirror, the sensor.yaml
// calibrate writes loads, and every fitted corner still projects inside the rim. Before,
// the start's rim was kept (hyperboloid-800x600 renders, --lens pinhole: a rim of 30 mm
// on a mirror seen edge-on from 14.7 mm, a sensor.yaml nothing could load).
TEST(BundleFit, ARimPastWhatTheLensSeesIsDrawnInToAValidMirror) {
  const Truth truth =
      ExactObservations(LoadSensorYaml(testing::SourceDir() + "/datasets-synthetic/sensors/ohte-edi.yaml"));
  SensorModel model = truth.sensor.model();
  std::visit([](auto& m) { m.rim_radius_mm *= 3.0; }, model);
  const Sensor start(model);
  ASSERT_FALSE(ValidateSensorModel(start.model()).empty());  // the case this test is about
  const FitResult fit =
      FitSensor(start, truth.target, truth.detections, StartingPoses(start, truth), FitOptions::DefaultsFor(start));
  ASSERT_TRUE(fit.sensor.has_value());
  EXPECT_LT(fit.rms_px, 1e-6) << fit.solver_report;
  EXPECT_EQ(ValidateSensorModel(fit.sensor->model()), "");
  EXPECT_LT(fit.sensor->rim_radius_mm(), start.rim_radius_mm());
  // Inside the widest valid rim by the 1 % FittedModel leaves (rays graze the mirror there).
  EXPECT_NE(ValidateSensorModel(SensorWithWiderRim(*fit.sensor, 1.02).model()), "");
  std::map<int, Eigen::Vector3d> board_mm;
  for (const TargetCorner& corner : truth.target.corners()) board_mm[corner.id] = corner.point_in_target;
  int projected = 0;
  for (size_t v = 0; v < truth.detections.images.size(); ++v)
    for (const CornerObservation& corner : truth.detections.images[v].corners) {
      const TargetPose& pose = fit.poses[v];
      Eigen::Vector2d pixel;
      const Eigen::Vector3d point =
          pose.camera_from_target_rotation * board_mm.at(corner.id) + pose.camera_from_target_translation_mm;
      EXPECT_EQ(fit.sensor->Project(point, &pixel), ProjectionStatus::kOk) << v << " " << corner.id;
      ++projected;
    }
  EXPECT_EQ(projected, fit.observations);
}

// A board bent by 3 mm along x and -2 mm along y (a paper sheet's sag over 0.2 m): exact
// corners of it give back the warp with the sensor, to the exact-observation tolerances
// (1e-6 px RMS; 1e-5 mm on the warp: a 1e-5 mm sag moves a corner by ~1e-6 px at these
// distances), while a flat-board fit of the same corners is visibly off.
TEST(BundleFit, RecoversABoardWarpFromExactObservations) {
  const Sensor truth_sensor = LoadSensorYaml(testing::SourceDir() + "/datasets-synthetic/sensors/ohte-sph-misaligned.yaml");
  const BoardWarp warp{3.0, -2.0};
  const Truth truth = WarpedObservations(truth_sensor, warp);
  // From the true sensor and a flat board: the warp has to come from the data (convergence
  // from a poor sensor guess is the other tests' subject).
  const Sensor& guess = truth.sensor;
  FitOptions options = FitOptions::DefaultsFor(guess);
  options.fit_board_warp = true;
  const FitResult fit = FitSensor(guess, truth.target, truth.detections, StartingPoses(guess, truth), options);
  ASSERT_TRUE(fit.board_warp.has_value());
  EXPECT_LT(fit.rms_px, 1e-6) << fit.solver_report;
  EXPECT_NEAR(fit.board_warp->warp.x_mm, 3.0, 1e-5);
  EXPECT_NEAR(fit.board_warp->warp.y_mm, -2.0, 1e-5);
  EXPECT_TRUE(std::isfinite(fit.board_warp->std_x_mm) && std::isfinite(fit.board_warp->std_y_mm));

  FitOptions flat_options = FitOptions::DefaultsFor(guess);
  flat_options.solver.max_num_iterations = 10;  // enough to settle; the misfit is what is measured
  const FitResult flat = FitSensor(guess, truth.target, truth.detections, StartingPoses(guess, truth), flat_options);
  EXPECT_FALSE(flat.board_warp.has_value());
  EXPECT_GT(flat.rms_px, 0.05);  // a 3 mm sag at 0.2-1.3 m moves corners by tenths of a px
}

// The warp of the test above (3 mm, -2 mm) plus a relief: a Gaussian bump of bump_mm at
// the board's corner of highest x and y, a quarter of the board's width wide.
BoardWarp BumpedWarp(const CalibrationTarget& board, double bump_mm) {
  const WarpedSurface extent = WarpedSurface::Of(board, BoardWarp());
  const double width_mm = (extent.high_mm - extent.low_mm).maxCoeff();
  BoardWarp warp{3.0, -2.0};
  for (const TargetCorner& c : board.corners())
    warp.relief_mm[c.id] = bump_mm * std::exp(-(c.point_in_target.head<2>() - extent.high_mm).squaredNorm() /
                                              (2.0 * std::pow(0.25 * width_mm, 2)));
  return warp;
}

// A board the paraboloid cannot describe: the warp above plus a 1.5 mm bump at one corner
// of the card (a Gaussian a quarter of the board wide), the board's relief
// (BoardWarp::relief_mm). From exact corners the fit with the relief gives the board's
// shape back: the relief is held orthogonal to a constant (the board moved along its
// normal, which every pose takes up) and to the warp's paraboloids
// (calib/board_relief_gauge.h), so it is the truth's relief less its projection onto those
// three shapes, up to a plane (a tilt of the board, which the poses take up to first
// order: what is left of it here the prior settles). 1e-4 mm: the exact-observation
// tolerance of the warp test above with the prior's pull on top (weighted by the corner
// noise, ~1e-6 px here). The warp alone leaves the bump in the residuals.
TEST(BundleFit, RecoversABoardsReliefFromExactObservations) {
  const Sensor truth_sensor =
      LoadSensorYaml(testing::SourceDir() + "/datasets-synthetic/sensors/ohte-sph-misaligned.yaml");
  const std::vector<SceneView> views = MixedDistanceViews(truth_sensor);
  const CalibrationTarget& board = *views[0].targets[0].target;
  const BoardWarp warp = BumpedWarp(board, 1.5);
  const Truth truth = WarpedObservations(truth_sensor, warp);
  FitOptions options = FitOptions::DefaultsFor(truth.sensor);
  options.fit_board_warp = options.fit_board_relief = true;
  const FitResult fit =
      FitSensor(truth.sensor, truth.target, truth.detections, StartingPoses(truth.sensor, truth), options);
  ASSERT_TRUE(fit.board_warp.has_value());
  EXPECT_LT(fit.rms_px, 1e-6) << fit.solver_report;
  const std::map<int, Eigen::Vector2d> basis = BoardWarp::Basis(board);
  ASSERT_EQ(fit.board_warp->warp.relief_mm.size(), board.corners().size());
  const int corners = static_cast<int>(board.corners().size());
  Eigen::MatrixXd gauge(corners, 3), planes(corners, 5);  // 1 and the two paraboloids; and x, y
  Eigen::VectorXd fitted(corners), true_relief(corners);
  int row = 0;
  for (const TargetCorner& c : board.corners()) {
    gauge.row(row) << 1.0, basis.at(c.id).x(), basis.at(c.id).y();
    planes.row(row) << gauge.row(row), c.point_in_target.x(), c.point_in_target.y();
    fitted(row) = fit.board_warp->warp.relief_mm.at(c.id);
    true_relief(row++) = warp.relief_mm.at(c.id);
  }
  EXPECT_LT((gauge * gauge.colPivHouseholderQr().solve(fitted)).cwiseAbs().maxCoeff(), 1e-6);  // no mean, no paraboloid
  const Eigen::VectorXd difference = fitted - true_relief;
  const Eigen::VectorXd beyond = difference - planes * planes.colPivHouseholderQr().solve(difference);
  EXPECT_LT(beyond.cwiseAbs().maxCoeff(), 1e-4);
  const Eigen::VectorXd bump = true_relief - planes * planes.colPivHouseholderQr().solve(true_relief);
  EXPECT_GT(bump.cwiseAbs().maxCoeff(), 0.5);  // the bump is mostly not those shapes: the check has teeth
  ASSERT_TRUE(fit.covariance_ok);
  for (const auto& [id, std_mm] : fit.board_warp->relief_std_mm) EXPECT_TRUE(std::isfinite(std_mm)) << id;

  FitOptions warp_only = FitOptions::DefaultsFor(truth.sensor);
  warp_only.fit_board_warp = true;
  const FitResult without =
      FitSensor(truth.sensor, truth.target, truth.detections, StartingPoses(truth.sensor, truth), warp_only);
  ASSERT_TRUE(without.board_warp.has_value());
  EXPECT_TRUE(without.board_warp->warp.relief_mm.empty());
  EXPECT_TRUE(without.converged) << without.solver_report;
  EXPECT_GT(without.rms_px, 0.02);  // a 1.5 mm bump at 0.2-1.3 m moves its corners by tenths of a px
}

// What the relief is for: under 0.3 px of corner noise, a board bent beyond the paraboloid
// (the 1.5 mm bump above) bends the warp-only fit's sensor away from the truth, and the
// relief takes that back; on a board the paraboloid describes it costs a little variance.
// Measured from the truth at 300 mm over the detected field (after the best rigid
// alignment), seeds 1 / 2: the bump warp-only 0.158 / 0.134 px, with the relief 0.093 /
// 0.068 (bounded at 0.75 x); the paraboloid board seed 1 0.083 against 0.086 (bounded at
// 1.15 x; seeds 2, 3: 1.06 x). Why the folds choose it (calib/relief_choice.h) rather than
// always fitting it.
TEST(BundleFit, ABentBoardsReliefBringsTheSensorNearerTheTruth) {
  const Sensor truth_sensor =
      LoadSensorYaml(testing::SourceDir() + "/datasets-synthetic/sensors/ohte-sph-misaligned.yaml");
  const std::vector<SceneView> views = MixedDistanceViews(truth_sensor);
  const CalibrationTarget& board = *views[0].targets[0].target;
  // From the truth at 300 mm, fitted with the warp alone and with the relief.
  auto from_truth_px = [&](double bump_mm, int seed) {
    Truth truth = WarpedObservations(truth_sensor, BumpedWarp(board, bump_mm));
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, 0.3);
    for (ImageDetections& image : truth.detections.images)
      for (CornerObservation& c : image.corners) c.pixel += Eigen::Vector2d(noise(rng), noise(rng));
    const std::vector<Eigen::Vector2d> field = ComparisonField(truth.sensor, &truth.detections, 16.0);
    std::array<double, 2> px{};
    for (int relief = 0; relief < 2; ++relief) {
      FitOptions options = FitOptions::DefaultsFor(truth.sensor);
      options.fit_board_warp = true;
      options.fit_board_relief = relief == 1;
      const FitResult fit =
          FitSensor(truth.sensor, truth.target, truth.detections, StartingPoses(truth.sensor, truth), options);
      EXPECT_TRUE(fit.sensor.has_value());
      if (fit.sensor) px[relief] = CompareProjections(truth.sensor, *fit.sensor, field, 300.0).rms_px;
    }
    return px;
  };
  for (int seed : {1, 2}) {
    const std::array<double, 2> bent = from_truth_px(1.5, seed);
    EXPECT_LT(bent[1], 0.75 * bent[0]) << "seed " << seed << ": warp only " << bent[0] << ", relief " << bent[1];
  }
  const std::array<double, 2> paraboloid = from_truth_px(0.0, 1);
  EXPECT_LT(paraboloid[1], 1.15 * paraboloid[0]) << paraboloid[0] << " " << paraboloid[1];
}

// With 0.3 px of corner noise the fitted warp lies within 4 of its reported standard
// deviations of the truth (a 6e-5 event for a Gaussian estimate; one fixed seed).
TEST(BundleFit, BoardWarpStandardDeviationsHoldUnderNoise) {
  const Sensor truth_sensor = LoadSensorYaml(testing::SourceDir() + "/datasets-synthetic/sensors/ohte-sph-misaligned.yaml");
  Truth truth = WarpedObservations(truth_sensor, BoardWarp{3.0, -2.0});
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.3);
  for (ImageDetections& image : truth.detections.images)
    for (CornerObservation& c : image.corners) c.pixel += Eigen::Vector2d(noise(rng), noise(rng));
  FitOptions options = FitOptions::DefaultsFor(truth.sensor);
  options.fit_board_warp = true;
  const FitResult fit = FitSensor(truth.sensor, truth.target, truth.detections, StartingPoses(truth.sensor, truth), options);
  ASSERT_TRUE(fit.board_warp.has_value());
  ASSERT_TRUE(fit.covariance_ok);
  EXPECT_LT(std::abs(fit.board_warp->warp.x_mm - 3.0), 4.0 * fit.board_warp->std_x_mm) << fit.board_warp->std_x_mm;
  EXPECT_LT(std::abs(fit.board_warp->warp.y_mm + 2.0), 4.0 * fit.board_warp->std_y_mm) << fit.board_warp->std_y_mm;
  EXPECT_LT(fit.board_warp->std_x_mm, 1.0);  // determined: the 3 mm sag is measured, not guessed
}

// The fit's corners evaluated on several threads (calib/parallel_evaluation.h) give the
// very numbers one thread gives: bit for bit, through noise, outlier removal (residual
// blocks removed mid-fit) and the covariance. A stale cache, or a thread-dependent sum,
// would differ in the last digits at least.
TEST(BundleFit, ThreadCountChangesNoDigit) {
  const Truth truth = ExactObservations(LoadSensorYaml(testing::SourceDir() + "/datasets-synthetic/sensors/ohte-sph-misaligned.yaml"));
  const Sensor guess = Perturbed(truth.sensor);
  DetectionSet noisy = truth.detections;
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.3);
  int corner = 0;
  for (ImageDetections& image : noisy.images)
    for (CornerObservation& c : image.corners) {
      c.pixel += Eigen::Vector2d(noise(rng), noise(rng));
      if (++corner % 37 == 0) c.pixel.x() += 25.0;  // gross outliers, removed mid-fit
    }
  const std::vector<TargetPose> poses = StartingPoses(guess, {truth.sensor, truth.target, noisy});
  FitOptions options = FitOptions::DefaultsFor(guess);
  const FitResult one = FitSensor(guess, truth.target, noisy, poses, options);
  options.threads = 3;
  const FitResult three = FitSensor(guess, truth.target, noisy, poses, options);
  ASSERT_TRUE(one.sensor.has_value() && three.sensor.has_value());
  ASSERT_TRUE(one.covariance_ok && three.covariance_ok);
  EXPECT_GT(one.outliers, 10);
  EXPECT_EQ(one.outliers, three.outliers);
  EXPECT_EQ(one.rms_px, three.rms_px);
  EXPECT_EQ(one.solver_report, three.solver_report);
  ASSERT_EQ(one.parameters.size(), three.parameters.size());
  for (size_t k = 0; k < one.parameters.size(); ++k) {
    EXPECT_EQ(one.parameters[k].value, three.parameters[k].value) << one.parameters[k].name;
    EXPECT_EQ(one.parameters[k].std, three.parameters[k].std) << one.parameters[k].name;
  }
  for (size_t v = 0; v < one.poses.size(); ++v)
    EXPECT_EQ(one.poses[v].camera_from_target_translation_mm, three.poses[v].camera_from_target_translation_mm) << v;
}

// The parallel evaluation's cache (calib/parallel_evaluation.h) answers only what it
// computed, at the values it computed it: a block made variable after the cache was
// filled without its Jacobian, or parameters moved without a new preparation, send the
// cost back to evaluating itself (r = x y + 2 y: dr/dx = y, dr/dy = x + 2).
struct Product {
  template <typename T>
  bool operator()(const T* x, const T* y, T* residual) const {
    residual[0] = x[0] * y[0] + 2.0 * y[0];
    return true;
  }
};

TEST(ParallelEvaluation, TheCacheNeverAnswersWhatItDidNotCompute) {
  ParallelEvaluation evaluation(2);  // before the problem, which owns the cost
  ceres::Problem::Options problem_options;
  problem_options.evaluation_callback = &evaluation;
  ceres::Problem problem(problem_options);
  double x = 1.5, y = 0.5;
  ceres::CostFunction* cost =
      evaluation.Wrap(new ceres::AutoDiffCostFunction<Product, 1, 1, 1>(new Product), std::vector<double*>{&x, &y});
  problem.AddResidualBlock(cost, nullptr, &x, &y);
  problem.SetParameterBlockConstant(&y);
  evaluation.UpdateConstantBlocks(problem);
  evaluation.PrepareForEvaluation(true, true);  // the cache: r and dr/dx only
  problem.SetParameterBlockVariable(&y);
  evaluation.UpdateConstantBlocks(problem);
  double residual = NAN, dx = NAN, dy = NAN;
  double* jacobians[2] = {&dx, &dy};
  const double* parameters[2] = {&x, &y};
  ASSERT_TRUE(cost->Evaluate(parameters, &residual, jacobians));
  EXPECT_EQ(residual, 1.75);
  EXPECT_EQ(dx, 0.5);
  EXPECT_EQ(dy, 3.5);
  evaluation.PrepareForEvaluation(true, true);  // now both blocks
  x = 2.0;  // moved without a new preparation
  ASSERT_TRUE(cost->Evaluate(parameters, &residual, jacobians));
  EXPECT_EQ(residual, 2.0);
  EXPECT_EQ(dy, 4.0);
}

// The cost keeps the last reflection point to skip the solve in the Jet passes that share
// its parameter values (model/catadioptric.h, SolvedReflection). Whatever it evaluated
// before, its residual and Jacobian must be those of a fresh cost, bit for bit.
TEST(ReprojectionCost, AnswersAsAFreshCostWhateverItEvaluatedBefore) {
  using Model = Catadioptric<double, SphereProfile, PinholeLens>;
  const Sensor sensor = LoadSensorYaml(testing::SourceDir() + "/datasets-synthetic/sensors/ohte-sph-misaligned.yaml");
  const Model& model = std::get<Model>(sensor.model());
  const Truth truth = ExactObservations(sensor);
  const ImageDetections& image = truth.detections.images[0];
  TargetPose pose;
  ASSERT_TRUE(InitialTargetPose(sensor, truth.target, image, &pose));
  SensorBlocks<Model> blocks(model);
  const Eigen::Quaterniond& q = pose.camera_from_target_rotation;
  std::array<double, 4> rotation = {q.x(), q.y(), q.z(), q.w()};
  std::array<double, 3> translation = {pose.camera_from_target_translation_mm.x(), pose.camera_from_target_translation_mm.y(),
                                       pose.camera_from_target_translation_mm.z()};
  std::vector<double*> parameters = blocks.Pointers();
  parameters.push_back(rotation.data());
  parameters.push_back(translation.data());
  const auto found = std::find_if(truth.target.corners().begin(), truth.target.corners().end(),
                                  [&](const TargetCorner& c) { return c.id == image.corners[5].id; });
  ASSERT_NE(found, truth.target.corners().end());
  const Eigen::Vector3d corner = found->point_in_target;
  const std::unique_ptr<ceres::CostFunction> fresh(CreateReprojectionCost(model, corner, image.corners[5].pixel));
  const std::vector<int32_t> sizes = fresh->parameter_block_sizes();
  ASSERT_EQ(sizes.size(), parameters.size());
  struct Answer {
    std::array<double, 2> residual;
    std::vector<std::vector<double>> jacobians;
  };
  auto evaluate = [&](const ceres::CostFunction& cost, bool with_jacobians) {
    Answer answer;
    std::vector<double*> jacobians;
    for (int size : sizes) answer.jacobians.emplace_back(2 * size, NAN);
    for (auto& j : answer.jacobians) jacobians.push_back(j.data());
    EXPECT_TRUE(cost.Evaluate(parameters.data(), answer.residual.data(), with_jacobians ? jacobians.data() : nullptr));
    return answer;
  };
  const Answer expected = evaluate(*fresh, true);
  // A plain residual takes the double root itself, a Jacobian one more Newton step in Jets:
  // the two agree to rounding only, so each is compared with its own kind.
  const std::unique_ptr<ceres::CostFunction> fresh_plain(
      CreateReprojectionCost(model, corner, image.corners[5].pixel));
  const Answer expected_plain = evaluate(*fresh_plain, false);
  const std::unique_ptr<ceres::CostFunction> used(
      CreateReprojectionCost(model, corner, image.corners[5].pixel));
  // Elsewhere first (another m and tilt), then a plain residual, then twice the Jacobian.
  const double m = parameters[1][0], tilt = parameters[2][0];
  parameters[1][0] += 0.7, parameters[2][0] += 0.01;
  evaluate(*used, true);
  parameters[1][0] = m, parameters[2][0] = tilt;
  const Answer plain = evaluate(*used, false);
  EXPECT_EQ(plain.residual, expected_plain.residual);
  for (int pass = 0; pass < 2; ++pass) {
    const Answer again = evaluate(*used, true);
    EXPECT_EQ(again.residual, expected.residual) << pass;
    EXPECT_EQ(again.jacobians, expected.jacobians) << pass;
  }
  EXPECT_NE(expected.jacobians[1][0], 0.0);  // m moves the pixel
}

TEST(RefineOptions, HoldsBlocksByTheirNamesAndRejectsUnknownOnes) {
  RefineOptions refine;
  EXPECT_NE(refine.Hold({"lens", "focal"}).find("unknown block 'focal'"), std::string::npos);
  refine = RefineOptions();
  EXPECT_EQ(refine.Hold({"lens", "m"}), "");
  EXPECT_FALSE(refine.focal || refine.principal_point || refine.distortion || refine.tangential || refine.m);
  EXPECT_TRUE(refine.tilt && refine.decenter && refine.shape && refine.poses);
  EXPECT_EQ(refine.HeldNames(), (std::set<std::string>{"lens", "m"}));
  refine = RefineOptions();
  EXPECT_EQ(refine.Hold({"principal_point", "distortion"}), "");
  EXPECT_EQ(refine.HeldNames(), (std::set<std::string>{"distortion", "principal_point"}));
  EXPECT_TRUE(refine.RefinesSensor());
  // Held by a pinhole's defaults, the tangential terms are named; the whole lens only with them.
  refine.tangential = false;
  EXPECT_EQ(refine.HeldNames(), (std::set<std::string>{"distortion", "principal_point", "tangential"}));
  EXPECT_EQ(refine.Hold({"lens"}), "");
  EXPECT_EQ(refine.HeldNames(), (std::set<std::string>{"lens"}));
  const RefineOptions poses = RefineOptions::PosesOnly();
  EXPECT_FALSE(poses.RefinesSensor());
  EXPECT_TRUE(poses.poses);
  EXPECT_EQ(poses.HeldNames(), (std::set<std::string>{"lens", "m", "tilt", "decenter", "shape"}));
  refine = RefineOptions();
  EXPECT_EQ(refine.Hold({"lens", "m", "tilt", "decenter"}), "");
  EXPECT_TRUE(refine.RefinesSensor());  // the shape is still free
}

TEST(FitOptions, CheckRefusesInvalidSolverSettings) {
  FitOptions options;
  EXPECT_EQ(options.Check(), "");
  options.solver.max_num_iterations = 0;
  EXPECT_EQ(options.Check(), "max_iterations: must be >= 1");
  options = FitOptions();
  options.solver.function_tolerance = -1.0;
  EXPECT_EQ(options.Check().rfind("solver: ", 0), 0u) << options.Check();
  options = FitOptions();
  options.threads = 0;
  EXPECT_EQ(options.Check(), "threads: must be >= 1");
  options.threads = 2;
  options.solver.use_inner_iterations = true;
  EXPECT_EQ(options.Check(), "threads: more than 1 needs solver.use_inner_iterations off");
}

// The parsimony rule over the counts not excluded (calibrate re-applies it when the
// folds' count fits the full set to no valid mirror). Scores as an earlier version of
// cli.figure_error_spline measured (focal length free): 12 is within 1 % of 16's lowest,
// 8 is not.
TEST(KnotChoice, PreferredCountIsTheFewestWithinOnePercentOfTheRest) {
  KnotChoice choice;
  choice.candidates = kKnotCandidates;
  choice.held_out_rms_px = {0.6724, 0.2017, 0.1570, 0.1423, 0.1407, 0.1406};
  std::vector<bool> tried(6, false);
  EXPECT_EQ(PreferredKnotCount(choice, tried), 4);  // 12 knots
  tried[4] = true;
  EXPECT_EQ(PreferredKnotCount(choice, tried), 5);  // 16: the lowest left, 8 is 1.2 % above it
  tried[5] = true;
  EXPECT_EQ(PreferredKnotCount(choice, tried), 3);  // 8
  choice.held_out_rms_px[2] = NAN;                   // a count whose folds failed is never picked
  tried = {false, true, false, true, true, true};
  EXPECT_EQ(PreferredKnotCount(choice, tried), 0);
  tried[0] = true;
  EXPECT_EQ(PreferredKnotCount(choice, tried), -1);
}

// After the folds, calibrate fits the full set with their count and, where that fit is no
// valid mirror, with the next preferred count (FitValidKnotCount). The fits are stand-ins
// here, so every branch runs deterministically: a valid spline (BumpedSplineProfile) or
// the same spline dented 20-fold inwards, which the sensor check refuses (z' or z'' <= 0
// before the rim; tests/spline_profile_test.cc finds where a dent starts to be refused).
// Each fit's rms_px is its count and its start's m is 100 mm + the count, to tell which
// fit and which start came back.
TEST(KnotChoice, AFullFitThatIsNoValidMirrorIsReplacedByTheNextPreferredCount) {
  const Sensor valid(testing::MakeModel<SplineProfile, PinholeLens>(testing::BumpedSplineProfile(), 180.0, false));
  SplineProfile<double> dented = testing::BumpedSplineProfile();
  for (int k = 0; k < dented.num_knots; ++k) dented.knots_mm[k] *= -20.0;
  const Sensor invalid(testing::MakeModel<SplineProfile, PinholeLens>(dented, 180.0, false));
  ASSERT_EQ(ValidateSensorModel(valid.model()), "");
  ASSERT_NE(ValidateSensorModel(invalid.model()), "");

  KnotChoice choice;  // the scores above: 12 preferred, then 16, then 8
  choice.base_profile = "sphere";
  choice.candidates = kKnotCandidates;
  choice.held_out_rms_px = {0.6724, 0.2017, 0.1570, 0.1423, 0.1407, 0.1406};
  choice.chosen = 12;
  enum class Outcome { kValid, kInvalid, kNoFit };
  std::map<int, Outcome> outcome;
  std::vector<int> asked;
  const auto fit_count = [&](int knots) {
    asked.push_back(knots);
    FitResult fit;
    fit.rms_px = knots;
    fit.solver_report = "report of " + std::to_string(knots);
    const Outcome o = outcome.count(knots) ? outcome[knots] : Outcome::kValid;
    if (o != Outcome::kNoFit) fit.sensor = o == Outcome::kValid ? valid : invalid;
    return KnotCountFit{std::move(fit),
                        Sensor(testing::MakeModel<SplineProfile, PinholeLens>(testing::BumpedSplineProfile(), 100.0 + knots,
                                                                             false))};
  };
  const auto start_m_mm = [](const Sensor& start) {
    for (const ParameterEstimate& p : SensorParameters(start))
      if (p.name == "m_mm") return p.value;
    return double(NAN);
  };

  // Runs the rule with these fits' outcomes; checks which counts it fitted, in order.
  const auto run = [&](std::map<int, Outcome> outcomes, const std::vector<int>& expected_asked) {
    outcome = std::move(outcomes);
    asked.clear();
    ValidKnotFit result = FitValidKnotCount(choice, "sphere", fit_count);
    EXPECT_EQ(asked, expected_asked);
    return result;
  };
  // The fit it kept: its count (the stand-in's rms_px says which fit came back), whether
  // valid, and what it says.
  const auto expect_kept = [&](const ValidKnotFit& result, int knots, bool valid, const std::string& replaced) {
    ASSERT_TRUE(result.fitted);
    EXPECT_EQ(result.valid, valid);
    EXPECT_EQ(result.knots, knots);
    EXPECT_EQ(result.fitted->fit.rms_px, knots);
    EXPECT_NEAR(start_m_mm(result.fitted->start), 100.0 + knots, 1e-9);
    EXPECT_EQ(result.replaced, replaced);
  };
  const Outcome no = Outcome::kInvalid;

  // The folds' count is a valid mirror: fitted once, nothing replaced.
  expect_kept(run({}, {12}), 12, true, "");
  // 12 and 16 bend past a mirror: 8, the next by the same rule, is fitted and said so.
  expect_kept(run({{12, no}, {16, no}}, {12, 16, 8}), 8, true,
              "the full set fitted with 12 knots (no valid mirror), 16 knots (no valid mirror); 8 knots, the folds' "
              "next choice, fitted instead");
  // No count is a valid mirror: the folds' own (the first that fitted) is kept, invalid;
  // nothing is said here (calibrate warns that the sensor fails validation).
  const std::map<int, Outcome> none_valid = {{0, no}, {4, no}, {6, no}, {8, no}, {12, no}, {16, no}};
  expect_kept(run(none_valid, {12, 16, 8, 6, 4, 0}), 12, false, "");
  // The folds' count does not fit at all and no other is valid: the first that fitted
  // (16), with both said.
  std::map<int, Outcome> outcomes = none_valid;
  outcomes[12] = Outcome::kNoFit;
  expect_kept(run(outcomes, {12, 16, 8, 6, 4, 0}), 16, false,
              "the full set fitted with 12 knots (no fit), 16 knots (no valid mirror), 8 knots (no valid mirror), 6 "
              "knots (no valid mirror), 4 knots (no valid mirror), sphere (no valid mirror); 16 knots, the folds' next "
              "choice, fitted instead (no valid mirror either)");
  // Nothing fits: no sensor, the first failure's report for calibrate's error.
  for (auto& entry : outcomes) entry.second = Outcome::kNoFit;
  const ValidKnotFit nothing = run(outcomes, {12, 16, 8, 6, 4, 0});
  EXPECT_FALSE(nothing.fitted);
  ASSERT_TRUE(nothing.failed);
  EXPECT_EQ(nothing.failed->solver_report, "report of 12");
  EXPECT_EQ(nothing.knots, 12);
  EXPECT_EQ(nothing.replaced, "");
  // Where the base family is the next preferred, it replaces the spline under its name.
  choice.held_out_rms_px = {0.1410, 0.2017, 0.1570, 0.1423, 0.1390, 0.1500};  // 12; then the sphere
  expect_kept(run({{12, no}}, {12, 0}), 0, true,
              "the full set fitted with 12 knots (no valid mirror); the sphere mirror, the folds' next choice, fitted "
              "instead");
}

// A spline's c1 is a near-gauge where few corners reflect inside its first two knot
// spacings (past them its knots reproduce c1 r^2): the fit then holds it at its fitted value
// for the covariance (calib/bundle_fit.cc, VertexCurvatureIsANearGauge), which otherwise is
// near-singular along that valley; where the views reach near the axis, c1 is determined
// and stays free. The bumped spline mirror (6 knots: the first two spacings end at 0.63 of
// the span), the mixed views with 0.1 px of noise per coordinate, every corner or only
// those reflecting beyond `min_radius_share` of the rim.
FitResult NoisySplineFit(double min_radius_share, bool hold_weak_vertex_curvature = true) {
  const Sensor truth_sensor(
      testing::MakeModel<SplineProfile, OrthographicLens>(testing::BumpedSplineProfile(), 180.0, false));
  Truth truth = MixedDistanceObservations(truth_sensor);
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 0.1);
  for (ImageDetections& image : truth.detections.images) {
    std::vector<CornerObservation> kept;
    for (const CornerObservation& corner : image.corners) {
      Eigen::Vector3d origin, direction;
      if (truth.sensor.Unproject(corner.pixel, &origin, &direction) != ProjectionStatus::kOk) continue;
      if (origin.head<2>().norm() < min_radius_share * testing::kRimMm) continue;  // the reflection point's radius
      kept.push_back({corner.id, corner.pixel + Eigen::Vector2d(noise(rng), noise(rng))});
    }
    image.corners = kept;
  }
  truth.detections.images.erase(std::remove_if(truth.detections.images.begin(), truth.detections.images.end(),
                                               [](const ImageDetections& image) { return image.corners.size() < 8; }),
                                truth.detections.images.end());
  std::vector<TargetPose> poses(truth.detections.images.size());
  for (size_t v = 0; v < poses.size(); ++v)
    EXPECT_TRUE(InitialTargetPose(truth.sensor, truth.target, truth.detections.images[v], &poses[v])) << v;
  // As calibrate fits it: m held (the orthographic lens's gauge), the scale held (scale x
  // mirror size is what the image shows).
  FitOptions options = FitOptions::DefaultsFor(truth.sensor);
  options.hold_weak_vertex_curvature = hold_weak_vertex_curvature;
  return FitSensor(truth.sensor, truth.target, truth.detections, poses, options);
}

const ParameterEstimate& Parameter(const FitResult& fit, const std::string& name) {
  const auto found = std::find_if(fit.parameters.begin(), fit.parameters.end(),
                                  [&](const ParameterEstimate& p) { return p.name == name; });
  EXPECT_NE(found, fit.parameters.end()) << name;
  return *found;
}

TEST(BundleFit, ASplinesVertexCurvatureSeenOnlyAsAGaugeIsHeldForTheCovariance) {
  const FitResult every = NoisySplineFit(0.0);
  ASSERT_TRUE(every.sensor.has_value()) << every.solver_report;
  ASSERT_TRUE(every.covariance_ok);
  EXPECT_FALSE(Parameter(every, "c1").fixed) << "c1 held where corners reach the axis";
  EXPECT_TRUE(std::isnan(every.vertex_curvature_std_ratio));

  const FitResult outer = NoisySplineFit(0.75);
  const FitResult outer_free = NoisySplineFit(0.75, false);
  for (const FitResult* fit : {&outer, &outer_free}) {
    ASSERT_TRUE(fit->sensor.has_value()) << fit->solver_report;
    ASSERT_TRUE(fit->covariance_ok);
  }
  // Held for the covariance only: the fit is the same, c1 fitted (free, its std not determined).
  EXPECT_EQ(Parameter(outer, "c1").value, Parameter(outer_free, "c1").value);
  EXPECT_EQ(outer.rms_px, outer_free.rms_px);
  EXPECT_FALSE(Parameter(outer, "c1").fixed);
  EXPECT_TRUE(std::isnan(Parameter(outer, "c1").std));
  EXPECT_EQ(std::count(outer.covariance_names.begin(), outer.covariance_names.end(), "c1"), 0);
  EXPECT_GT(outer.vertex_curvature_std_ratio, kWeakRelativeStd);
  // Free, c1's std is what the held fit recorded, and the knots' stds follow the valley.
  const double c1_std = Parameter(outer_free, "c1").std;
  EXPECT_NEAR(c1_std / std::abs(Parameter(outer_free, "c1").value), outer.vertex_curvature_std_ratio, 1e-9);
  double widest_held = 0.0, widest_free = 0.0;
  for (const ParameterEstimate& p : outer.parameters)
    if (p.name.rfind("knot", 0) == 0) {
      EXPECT_FALSE(p.fixed) << p.name;
      widest_held = std::max(widest_held, p.std);
      widest_free = std::max(widest_free, Parameter(outer_free, p.name).std);
    }
  std::printf("c1 std %.1f %%; widest knot std %.3f mm held, %.3f mm free\n",
              100.0 * outer.vertex_curvature_std_ratio, widest_held, widest_free);
  EXPECT_LT(widest_held, 0.5 * widest_free);
}

// The spline's knot count by held-out folds (calib/knot_choice.h), on corners with 0.1 px
// of noise per coordinate (0.141 px per corner): the mirror of BumpedSplineProfile (a
// 0.3 mm figure error in 6 knots) is one the 3-term polynomial cannot follow, so a spline
// must be chosen and predict the held-out views at the noise; a polynomial mirror needs
// no spline (the parsimony rule keeps it unless a spline predicts 1 % better). Both start
// from the truth converted to the polynomial, as a guess of the wrong family would be.
TEST(KnotChoice, ChoosesASplineOnlyWhereTheMirrorNeedsOne) {
  const double kNoisePerCornerPx = 0.1 * std::sqrt(2.0);
  const std::array<double, 3> kDistancesRimRadii = {2.0, 7.0, HUGE_VAL};
  std::array<double, 3> spline_vs_truth_rms_px, polynomial_vs_truth_rms_px;
  spline_vs_truth_rms_px.fill(NAN);
  polynomial_vs_truth_rms_px.fill(NAN);
  for (const testing::NamedSensor& named : testing::SensorsWithLens<OrthographicLens>("orthographic", false)) {
    const bool bumped = named.name.rfind("spline", 0) == 0;
    if (!bumped && named.name.rfind("polynomial", 0) != 0) continue;
    SCOPED_TRACE(named.name);
    Truth truth = MixedDistanceObservations(Sensor(named.model));
    truth.detections.images.resize(10);  // 10 views, 5 folds of 2: a real set's size
    std::mt19937 rng(5);
    std::normal_distribution<double> noise(0.0, 0.1);
    for (ImageDetections& image : truth.detections.images) {
      std::vector<CornerObservation> every_third;  // 48 of a view's 144 corners: the test's time
      for (size_t c = 0; c < image.corners.size(); c += 3) every_third.push_back(image.corners[c]);
      image.corners = every_third;
      for (CornerObservation& corner : image.corners) corner.pixel += Eigen::Vector2d(noise(rng), noise(rng));
    }
    const Sensor start = ConvertProfile(truth.sensor, "polynomial");
    std::vector<TargetPose> poses(truth.detections.images.size());
    for (size_t v = 0; v < poses.size(); ++v)
      ASSERT_TRUE(InitialTargetPose(start, truth.target, truth.detections.images[v], &poses[v])) << v;
    const KnotChoice choice = ChooseKnots(start, "polynomial", truth.target, truth.detections, poses, FitOptions());
    ASSERT_EQ(choice.candidates, kKnotCandidates);
    EXPECT_EQ(choice.folds, 5);
    double chosen_rms = NAN;
    std::string scores;
    for (size_t k = 0; k < choice.candidates.size(); ++k) {
      if (choice.candidates[k] == choice.chosen) chosen_rms = choice.held_out_rms_px[k];
      scores += " " + std::to_string(choice.candidates[k]) + ": " + std::to_string(choice.held_out_rms_px[k]);
    }
    SCOPED_TRACE("held-out RMS by knots (0: polynomial):" + scores);
    // Held out at the noise: 25 % above it allows for the poses fitted to 2 views per fold.
    EXPECT_LT(chosen_rms, 1.25 * kNoisePerCornerPx);
    if (bumped) {
      EXPECT_GT(choice.chosen, 0);
      EXPECT_GT(choice.held_out_rms_px[0], 2.0 * chosen_rms) << "the polynomial should miss the figure error";
    } else {
      EXPECT_EQ(choice.chosen, 0) << "a spline chosen for a polynomial mirror";
    }
    // The chosen model fitted to all 10 views against the true mirror over the observed field,
    // after the best rigid alignment (m is a gauge of the orthographic lens), as omnical diff
    // compares two calibrations.
    const Sensor chosen_start = bumped ? ConvertProfile(start, "spline", choice.chosen) : start;
    const FitResult fit = FitSensor(chosen_start, truth.target, truth.detections, poses, FitOptions());
    ASSERT_TRUE(fit.sensor.has_value()) << fit.solver_report;
    const std::vector<Eigen::Vector2d> field = ComparisonField(truth.sensor, &truth.detections, 24.0);
    for (size_t d = 0; d < kDistancesRimRadii.size(); ++d) {
      const double n = kDistancesRimRadii[d];
      const double distance_mm = std::isfinite(n) ? n * testing::kRimMm : kInfinityMm;
      const ProjectionDiff diff = CompareProjections(truth.sensor, *fit.sensor, field, distance_mm);
      EXPECT_GT(diff.compared, 100);
      (bumped ? spline_vs_truth_rms_px : polynomial_vs_truth_rms_px)[d] = diff.rms_px;
      // The 0.1 px, as RMS over the field, where the boards are (2 to 13 rim radii).
      if (std::isfinite(n)) {
        EXPECT_LT(diff.rms_px, 0.1) << "n = " << n << ", max " << diff.max_px << " px";
      }
    }
  }
  // Infinity is 0.19 px off for the spline and 0.47 px for the polynomial fitted to its own
  // mirror (measured): an extrapolation the 0.14 px noise and boards <= 13 radii away limit,
  // not the profile. So the bound there, and a check at every distance, is relative: the
  // flexible profile on a mirror no formula fits predicts as well as the exact formula on its
  // own mirror, from the same views and noise (ratios measured 0.91, 0.64, 0.40; 1.25 allows
  // for the noise draw).
  for (size_t d = 0; d < kDistancesRimRadii.size(); ++d)
    EXPECT_LT(spline_vs_truth_rms_px[d], 1.25 * polynomial_vs_truth_rms_px[d]) << "n = " << kDistancesRimRadii[d];
}

}  // namespace
}  // namespace omnical

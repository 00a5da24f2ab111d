// Generalisation measures (calib/cross_validation.h, calib/projection_diff.h): the rigid
// alignment of two calibrations recovers a known motion, held-out views through an exact
// calibration fit exactly and through a noisy one at the noise level, two halves of exact
// corners agree, and the results survive calibration.json.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <random>

#include "calib/calibrate.h"
#include "calib/calibration_json.h"
#include "calib/cross_validation.h"
#include "calib/image_file.h"
#include "calib/predicted_error.h"
#include "calib/projection_diff.h"
#include "calib/synthetic/ground_truth.h"
#include "model/input_error.h"
#include "model/io/sensor_yaml.h"
#include "test_sensors.h"

namespace omnical {
namespace {

// A paraboloid behind an orthographic lens, tilted and decentred; `extra_m_mm` moves the
// mirror along the lens axis.
Sensor OrthographicParaboloid(double extra_m_mm) {
  auto model = testing::MakeModel<ParaboloidProfile, OrthographicLens>({0.5 * testing::kRimMm}, 180.0, true);
  model.pose.m_mm += extra_m_mm;
  return Sensor(model);
}

TEST(EvenlySpreadIndices, TakeTheCentresOfEqualRuns) {
  EXPECT_EQ(EvenlySpreadIndices(10, 2), (std::vector<size_t>{2, 7}));
  EXPECT_EQ(EvenlySpreadIndices(10, 3), (std::vector<size_t>{1, 5, 8}));
  EXPECT_EQ(EvenlySpreadIndices(3, 5), (std::vector<size_t>{0, 1, 2}));
  EXPECT_TRUE(EvenlySpreadIndices(0, 2).empty());
}

TEST(CompareProjections, ACalibrationAgainstItselfDiffersByNothing) {
  const Sensor sensor = OrthographicParaboloid(0.0);
  const std::vector<Eigen::Vector2d> field = ComparisonField(sensor, nullptr, 25.0);
  ASSERT_GT(field.size(), 500u);
  const ProjectionDiff diff = CompareProjections(sensor, sensor, field, 1000.0);
  // Unproject then project through one sensor: the solvers' 1e-9 px round trip.
  EXPECT_LT(diff.rms_px, 1e-7);
  EXPECT_LT(diff.rotation_deg, 1e-6);
  EXPECT_LT(diff.translation_mm.norm(), 1e-6);
  EXPECT_EQ(diff.compared, static_cast<int>(field.size()));
}

// Behind an orthographic lens, moving the mirror by d along the axis is the same as moving
// every object by -d (the lens's rays are parallel to the axis, so only the mirror-object
// geometry matters). So the other sensor, aligned, must match to the solvers' precision
// with translation (0, 0, d) and no rotation, while unaligned it is visibly off at 300 mm.
TEST(CompareProjections, AlignmentFindsTheMotionThatMakesTwoSensorsOne) {
  const double shift_mm = 5.0;
  const Sensor reference = OrthographicParaboloid(0.0), moved = OrthographicParaboloid(shift_mm);
  const std::vector<Eigen::Vector2d> field = ComparisonField(reference, nullptr, 25.0);
  const ProjectionDiff diff = CompareProjections(reference, moved, field, 300.0);
  EXPECT_GT(diff.unaligned_rms_px, 0.5);  // 5 mm at 300 mm: about a degree of parallax
  EXPECT_TRUE(diff.aligned);
  // 1e-5 px: the alignment's central differences and solver tolerance, far below the
  // >0.5 px the motion caused.
  EXPECT_LT(diff.rms_px, 1e-5);
  EXPECT_LT(diff.rotation_deg, 1e-5);
  EXPECT_NEAR(diff.translation_mm.z(), shift_mm, 1e-4);
  EXPECT_NEAR(diff.translation_mm.x(), 0.0, 1e-4);
  EXPECT_NEAR(diff.translation_mm.y(), 0.0, 1e-4);
}

// Two different calibrations over the whole mirror, rim included: the alignment's steps
// push rim points a little past the rim, which must not stop it (it once reported the
// unaligned numbers there). Aligned it can only do better than unaligned.
TEST(CompareProjections, AlignsOverTheWholeMirrorUpToTheRim) {
  const Sensor reference(testing::MakeModel<SphereProfile, PinholeLens>({1.138 * testing::kRimMm}, 4.110 * testing::kRimMm, true));
  auto model = testing::MakeModel<SphereProfile, PinholeLens>({1.138 * testing::kRimMm}, 4.110 * testing::kRimMm, true);
  model.pose.decenter_x_mm += 0.5;
  model.lens.cx_px += 2.0;
  const Sensor other(model);
  const ProjectionDiff diff = CompareProjections(reference, other, ComparisonField(reference, nullptr, 25.0), 1000.0);
  EXPECT_TRUE(diff.aligned);
  EXPECT_GT(diff.unaligned_rms_px, 1.0);
  EXPECT_LT(diff.rms_px, 0.5 * diff.unaligned_rms_px);
}

// Without alignment the difference is the plain displacement predicted_error.h computes
// independently (point by point, no batch cost function).
TEST(CompareProjections, UnalignedIsThePlainDisplacement) {
  const Sensor reference = OrthographicParaboloid(0.0), moved = OrthographicParaboloid(2.0);
  const std::vector<Eigen::Vector2d> field = ComparisonField(reference, nullptr, 40.0);
  const ProjectionDiff diff = CompareProjections(reference, moved, field, 500.0, false);
  const std::vector<double> displacement = ProjectionDisplacement(reference, moved, field, 500.0);
  double square = 0.0;
  int count = 0;
  for (double d : displacement)
    if (std::isfinite(d)) square += d * d, ++count;
  EXPECT_EQ(diff.compared, count);
  EXPECT_NEAR(diff.rms_px, std::sqrt(square / count), 1e-9);
  EXPECT_FALSE(diff.aligned);
}

// At infinity a translation moves nothing: it is held at zero, and the shifted mirror's
// difference is the 5 mm seen from 1e8 mm away, nothing.
TEST(CompareProjections, AtInfinityOnlyTheRotationIsFitted) {
  const Sensor reference = OrthographicParaboloid(0.0), moved = OrthographicParaboloid(5.0);
  const ProjectionDiff diff = CompareProjections(reference, moved, ComparisonField(reference, nullptr, 40.0), kInfinityMm);
  EXPECT_EQ(diff.translation_mm.norm(), 0.0);
  EXPECT_LT(diff.rms_px, 1e-4);
}

// The same exact motion, fitted at 300 mm and carried to 2 m and to infinity: the two
// sensors still match there (a rigid motion of the frame is one at every distance), and
// the diff says where its alignment was fitted. Fitted at the compared distance itself
// (align_at_mm that distance, or NaN) the result is the same (one computation: 1e-12).
TEST(CompareProjections, AMotionFittedAtOneDistanceCarriesToEvery) {
  const Sensor reference = OrthographicParaboloid(0.0), moved = OrthographicParaboloid(5.0);
  const std::vector<Eigen::Vector2d> field = ComparisonField(reference, nullptr, 25.0);
  for (double distance_mm : {2000.0, kInfinityMm}) {
    const ProjectionDiff diff = CompareProjections(reference, moved, field, distance_mm, true, 300.0);
    EXPECT_TRUE(diff.aligned);
    EXPECT_EQ(diff.aligned_at_mm, 300.0);
    EXPECT_EQ(diff.compared, static_cast<int>(field.size()));
    EXPECT_LT(diff.rms_px, 1e-5) << distance_mm;  // as AlignmentFindsTheMotionThatMakesTwoSensorsOne
    EXPECT_NEAR(diff.translation_mm.z(), 5.0, 1e-4);
  }
  const ProjectionDiff here = CompareProjections(reference, moved, field, 2000.0);
  const ProjectionDiff named = CompareProjections(reference, moved, field, 2000.0, true, 2000.0);
  EXPECT_EQ(here.aligned_at_mm, 2000.0);
  EXPECT_NEAR(here.rms_px, named.rms_px, 1e-12);
  EXPECT_LT((here.translation_mm - named.translation_mm).norm(), 1e-12);
}

// A zoom-like difference (the lens's focal 0.5 % longer): fitted per distance, the
// alignment's translation grows with the distance and takes part of it up, and at infinity
// (rotation only) it cannot: the figure jumps. One alignment, fitted at the boards'
// 300 mm, reads the same at 99.9 km as at infinity. (Measured: per distance 0.75 px RMS at
// 99.9 km against 1.70 at infinity; aligned at 300 mm 1.70 and 1.70.)
TEST(CompareProjections, OneAlignmentIsContinuousIntoInfinity) {
  auto model =
      testing::MakeModel<SphereProfile, PinholeLens>({1.138 * testing::kRimMm}, 4.110 * testing::kRimMm, false);
  const Sensor reference(model);
  model.lens.fx_px *= 1.005;
  model.lens.fy_px *= 1.005;
  const Sensor zoomed(model);
  const std::vector<Eigen::Vector2d> field = ComparisonField(reference, nullptr, 25.0);
  const double far_mm = 0.999 * kInfinityMm;
  const ProjectionDiff once_far = CompareProjections(reference, zoomed, field, far_mm, true, 300.0);
  const ProjectionDiff once_infinity = CompareProjections(reference, zoomed, field, kInfinityMm, true, 300.0);
  const ProjectionDiff each_far = CompareProjections(reference, zoomed, field, far_mm);
  const ProjectionDiff each_infinity = CompareProjections(reference, zoomed, field, kInfinityMm);
  std::printf("RMS at 99.9 km / infinity: aligned at 300 mm %.4f / %.4f px, per distance %.4f / %.4f px\n",
              once_far.rms_px, once_infinity.rms_px, each_far.rms_px, each_infinity.rms_px);
  ASSERT_GT(once_infinity.rms_px, 0.1);  // the zoom shows
  EXPECT_NEAR(once_far.rms_px / once_infinity.rms_px, 1.0, 0.01);
  // The same motion at both (one fit at 300 mm): a translation of millimetres moves
  // nothing 100 km away.
  EXPECT_LT((once_far.translation_mm - once_infinity.translation_mm).norm(), 1e-12);
}

TEST(CompareProjections, RefusesWhatCannotBeCompared) {
  const Sensor sensor = OrthographicParaboloid(0.0);
  const std::vector<Eigen::Vector2d> field = ComparisonField(sensor, nullptr, 40.0);
  EXPECT_THROW(CompareProjections(sensor, sensor, field, 0.0), InputError);
  EXPECT_THROW(CompareProjections(sensor, sensor, field, NAN), InputError);
  try {
    CompareProjections(sensor, sensor, {Eigen::Vector2d(0.0, 0.0)}, 1000.0);  // a corner: no mirror there
    FAIL() << "no throw";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("field: only 0 field pixels"), std::string::npos) << error.what();
  }
  EXPECT_THROW(ComparisonField(sensor, nullptr, 0.0), InputError);
  for (double align_at_mm : {0.0, -5.0, 2.0 * kInfinityMm, HUGE_VAL}) {
    try {
      CompareProjections(sensor, sensor, field, 1000.0, true, align_at_mm);
      FAIL() << "no throw for align_at_mm " << align_at_mm;
    } catch (const InputError& error) {
      EXPECT_EQ(std::string(error.what()).rfind("align_at_mm: ", 0), 0u) << error.what();
    }
  }
  // Where to fit an alignment that is not made: refused, not ignored.
  try {
    CompareProjections(sensor, sensor, field, 1000.0, false, 300.0);
    FAIL() << "no throw for align_at_mm without the alignment";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()).rfind("align_at_mm: given without the alignment", 0), 0u) << error.what();
  }
}

// Fitted at one distance and carried to another, the motion can move points off the other
// sensor's mirror: those are counted and not compared, and before/after are over the same
// pixels. Two different mirrors (the sphere and the single-viewpoint hyperboloid of the
// seed paper) 10 mm from their reflection points, aligned at 100 mm: measured 2110 of 3043
// field pixels compared. At 1 mm none stays: refused.
TEST(CompareProjections, PointsMovedOffTheMirrorAreCountedNotCompared) {
  const std::string sensors = testing::SourceDir() + "/datasets-synthetic/sensors/";
  const Sensor sphere = LoadSensorYaml(sensors + "ohte-sph.yaml");
  const Sensor hyperboloid = LoadSensorYaml(sensors + "ohte-svp.yaml");
  const std::vector<Eigen::Vector2d> field = ComparisonField(sphere, nullptr, 16.0);
  const ProjectionDiff here = CompareProjections(sphere, hyperboloid, field, 10.0);
  const ProjectionDiff carried = CompareProjections(sphere, hyperboloid, field, 10.0, true, 100.0);
  EXPECT_EQ(here.moved_off_mirror, 0);  // fitted at 10 mm, the solver keeps every point on the mirror
  EXPECT_GT(carried.moved_off_mirror, 0);
  EXPECT_EQ(carried.compared + carried.moved_off_mirror, here.compared);
  int finite = 0;
  for (const Eigen::Vector2d& d : carried.difference_px) finite += d.allFinite();
  EXPECT_EQ(finite, carried.compared);
  // Unaligned over the compared pixels: their plain displacement.
  const std::vector<double> plain = ProjectionDisplacement(sphere, hyperboloid, field, 10.0);
  double square = 0.0;
  for (size_t k = 0; k < field.size(); ++k)
    if (carried.difference_px[k].allFinite()) square += plain[k] * plain[k];
  EXPECT_NEAR(carried.unaligned_rms_px, std::sqrt(square / carried.compared), 1e-6 * carried.unaligned_rms_px);
  try {
    CompareProjections(sphere, hyperboloid, field, 1.0, true, 100.0);
    FAIL() << "no throw with every point moved off the mirror";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()).rfind("align_at_mm: the rigid motion fitted there moves all but", 0), 0u)
        << error.what();
  }
}

// A fit that took the dolly-zoom gauge (a spline mirror with the focal length free: m 52 mm
// short, focal 28 % short) against the mirror it was fitted to (a sphere with a 20 um
// zonal figure error, a table): aligning them needs a 53 mm translation, on whose way
// field points pass within a difference step of the camera body's shadow. That once
// failed the alignment's Jacobian, ended the solve at its first accepted step and
// reported the unaligned numbers (28 px at 307 mm, where the fit is within 0.04 px).
TEST(CompareProjections, AlignsAcrossALargeGaugeMotionPastTheCameraBody) {
  const std::string dir = testing::PrivateTempDir();
  {
    std::ofstream table(dir + "/figure-error.csv");
    table.precision(12);
    const double a_mm = 49.9582, rim_mm = 43.9, error_mm = 0.020, pi = std::acos(-1.0);
    for (int i = 0; i <= 400; ++i) {
      const double r = 0.999 * a_mm * i / 400, root = std::sqrt(a_mm * a_mm - r * r), u = r * r / (rim_mm * rim_mm);
      table << r << "," << a_mm - root + error_mm * (std::cos(3 * pi * u) - 1) << ","
            << r / root - error_mm * std::sin(3 * pi * u) * 6 * pi * r / (rim_mm * rim_mm) << "\n";
    }
  }
  const Sensor truth = ParseSensorYaml(
      "camera: { model: pinhole, image_size: [1040, 1040], fx: 2352.41, fy: 2352.41, cx: 519.5, cy: 519.5, body_radius_mm: 15 }\n"
      "mirror: { profile: tabulated, table: figure-error.csv, rim_radius: 43.9 }\n"
      "pose: { m: 180.429, tilt_deg: [0.8, 0.6], decenter_mm: [0.48, -0.64] }\n",
      dir + "/truth.yaml");
  const Sensor fitted = ParseSensorYaml(
      "camera: { model: pinhole, image_size: [1040, 1040], fx: 1704.829, fy: 1704.880, cx: 527.319, cy: 509.296,"
      " body_radius_mm: 15 }\n"
      "mirror: { profile: spline, rim_radius: 45.21826, span: 45.21826, c1: 0.00969676, knots: [0.0300616, 0.254297,"
      " 0.740850, 1.509824, 2.578901, 4.064318, 6.183463, 9.201479] }\n"
      "pose: { m: 128.0663, tilt_deg: [0.56996, 0.41413], decenter_mm: [-0.10935, 0.13576] }\n",
      "fitted.yaml");
  const ProjectionDiff diff = CompareProjections(truth, fitted, ComparisonField(truth, nullptr, 16.0), 307.3);
  EXPECT_TRUE(diff.aligned);
  EXPECT_GT(diff.unaligned_rms_px, 10.0);
  EXPECT_NEAR(diff.translation_mm.z(), -52.8, 1.0);  // measured -52.81 (m's 52.4 mm gauge, and tilt)
  // Measured 0.035 px (the fit's own error there); 0.1 px is the bound.
  EXPECT_LT(diff.rms_px, 0.1);
}

// The committed render of the misaligned sphere (8 views) through its exact corners.
CalibrationInput InputFromTruth() {
  const std::string set = testing::SourceDir() + "/datasets-synthetic/rendered/ohte-sph-misaligned-near";
  std::vector<std::string> truth;
  for (const std::string& image : ListImages(set)) truth.push_back(image.substr(0, image.size() - 4) + ".json");
  CalibrationInput input;
  input.target_name = testing::SourceDir() + "/datasets-synthetic/targets/aprilgrid-6x6-30mm.yaml";
  input.target = CalibrationTarget::FromYaml(input.target_name);
  input.detections = DetectionsFromGroundTruth(truth);
  input.source = "ground truth";
  input.guess_name = testing::SourceDir() + "/datasets-synthetic/sensors/ohte-sph-misaligned-guess.yaml";
  input.guess = LoadSensorYaml(input.guess_name);
  return input;
}

// Exact corners: the sensor fitted on 6 views is the truth, so the 2 held-out views fit
// it exactly and two halves (3 views each) agree. Tolerances: 1e-3 px, the exact-corner
// tolerance of calibrate_api_test (solver convergence, 17-digit truth files).
TEST(CalibrateGeneralisation, ExactCornersHoldOutAndHalvesAgree) {
  CalibrationOptions options;
  options.holdout_views = 2;
  options.cross_validate = true;
  options.cross_validation_distance_mm = 1000.0;
  const CalibrationResult result = Calibrate(InputFromTruth(), options);
  const CalibrationRecord& record = result.record;
  ASSERT_TRUE(record.holdout);
  ASSERT_TRUE(record.cross_validation);
  EXPECT_EQ(record.holdout->images.size(), 2u);
  EXPECT_GT(record.holdout->corners, 50);
  EXPECT_LT(record.holdout->rms_px, 1e-3);
  EXPECT_EQ(result.views.images.size(), 6u);  // the held-out views are not fitted
  for (const std::string& image : record.holdout->images) EXPECT_EQ(record.per_view_rms_px.count(image), 0u) << image;
  const auto& cross = *record.cross_validation;
  EXPECT_EQ(cross.halves[0].size(), 3u);
  EXPECT_EQ(cross.halves[1].size(), 3u);
  EXPECT_LT(cross.half_rms_px[0], 1e-3);
  EXPECT_LT(cross.diff.rms_px, 1e-3);
  EXPECT_GT(cross.diff.compared, 100);
  EXPECT_EQ(cross.diff.distance_mm, 1000.0);
  // And with one alignment fitted where the boards were (the predicted error's first,
  // default distance), carried to 1000 mm: exact halves agree there too.
  ASSERT_TRUE(cross.diff_aligned_at_boards);
  ASSERT_FALSE(record.predicted_error.empty());
  EXPECT_EQ(cross.diff_aligned_at_boards->aligned_at_mm, record.predicted_error[0].distance_mm);
  EXPECT_EQ(cross.diff_aligned_at_boards->distance_mm, 1000.0);
  EXPECT_LT(cross.diff_aligned_at_boards->rms_px, 1e-3);

  // calibration.json keeps them.
  const CalibrationRecord back = ParseCalibrationJson(CalibrationJsonText(record), "calibration.json");
  ASSERT_TRUE(back.holdout && back.cross_validation);
  EXPECT_EQ(back.holdout->images, record.holdout->images);
  EXPECT_DOUBLE_EQ(back.holdout->rms_px, record.holdout->rms_px);
  EXPECT_EQ(back.holdout->corners, record.holdout->corners);
  EXPECT_EQ(back.cross_validation->halves, cross.halves);
  EXPECT_DOUBLE_EQ(back.cross_validation->diff.rms_px, cross.diff.rms_px);
  EXPECT_DOUBLE_EQ(back.cross_validation->diff.max_px, cross.diff.max_px);
  EXPECT_EQ(back.cross_validation->diff.compared, cross.diff.compared);
  EXPECT_EQ(back.cross_validation->diff.aligned_at_mm, 1000.0);
  ASSERT_TRUE(back.cross_validation->diff_aligned_at_boards);
  EXPECT_DOUBLE_EQ(back.cross_validation->diff_aligned_at_boards->rms_px, cross.diff_aligned_at_boards->rms_px);
  EXPECT_DOUBLE_EQ(back.cross_validation->diff_aligned_at_boards->aligned_at_mm,
                   cross.diff_aligned_at_boards->aligned_at_mm);
  EXPECT_EQ(CalibrationJsonText(back), CalibrationJsonText(record));  // every field read back
  EXPECT_DOUBLE_EQ(back.rms_all_px, record.rms_all_px);
}

// Gaussian corner noise of sigma per coordinate: a held-out view, its 6 pose parameters
// fitted to its ~2 x 100 coordinates, shows sqrt(2) sigma sqrt(1 - 6 / (2 n)) per corner,
// plus the training sensor's own error (small next to it with 6 views). The training views
// show about the same. 25 %: the bound for a model that generalises; a model that
// memorised the noise would show the training RMS well below the held-out one.
TEST(CalibrateGeneralisation, NoisyCornersHeldOutAtTheNoiseLevel) {
  const double sigma_px = 0.2;
  CalibrationInput input = InputFromTruth();
  std::mt19937 random(7);
  std::normal_distribution<double> noise(0.0, sigma_px);
  for (ImageDetections& image : input.detections->images)
    for (CornerObservation& corner : image.corners) corner.pixel += Eigen::Vector2d(noise(random), noise(random));
  CalibrationOptions options;
  options.holdout_views = 2;
  const CalibrationResult result = Calibrate(input, options);
  ASSERT_TRUE(result.record.holdout);
  const double per_corner_noise = std::sqrt(2.0) * sigma_px;
  EXPECT_NEAR(result.record.holdout->rms_px / per_corner_noise, 1.0, 0.25) << result.record.holdout->rms_px;
  EXPECT_NEAR(result.record.rms_all_px / per_corner_noise, 1.0, 0.25) << result.record.rms_all_px;
  EXPECT_NEAR(result.record.holdout->rms_px / result.record.rms_all_px, 1.0, 0.25);
  for (const CalibrationWarning& warning : result.warnings) EXPECT_NE(warning.code, WarningCode::kHeldOutWorse) << warning.text;
}

// A held-out view the sensor cannot predict is said (held_out_worse): here it carries 10 x
// the others' noise (0.05 vs 0.5 px per coordinate), so it fits at ~0.7 px against the
// training views' ~0.07 px, far past the 25 % the warning allows; the noisy set above,
// every view alike, is not warned of.
TEST(CalibrateGeneralisation, AHeldOutViewFarWorseThanTheTrainingViewsIsWarnedOf) {
  CalibrationInput input = InputFromTruth();
  const std::string noisy = input.detections->images[3].image;
  std::mt19937 random(11);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (ImageDetections& image : input.detections->images) {
    const double sigma_px = image.image == noisy ? 0.5 : 0.05;
    for (CornerObservation& corner : image.corners)
      corner.pixel += sigma_px * Eigen::Vector2d(noise(random), noise(random));
  }
  CalibrationOptions options;
  options.holdout_images = {noisy};
  const CalibrationResult result = Calibrate(input, options);
  ASSERT_TRUE(result.record.holdout);
  EXPECT_GT(result.record.holdout->rms_px, 5.0 * result.record.rms_all_px);
  int warned = 0;
  for (const CalibrationWarning& warning : result.warnings)
    if (warning.code == WarningCode::kHeldOutWorse) {
      ++warned;
      EXPECT_EQ(warning.text.rfind("the 1 held-out views fit at ", 0), 0u) << warning.text;
      EXPECT_NE(warning.text.find("the model does not predict new views as well as it fits its own"), std::string::npos)
          << warning.text;
    }
  EXPECT_EQ(warned, 1);
  // calibration.json keeps it among its warnings.
  EXPECT_EQ(std::count_if(result.record.warnings.begin(), result.record.warnings.end(),
                          [](const std::string& text) { return text.rfind("the 1 held-out views fit at ", 0) == 0; }),
            1);
}

TEST(CalibrateGeneralisation, RefusesTooFewViewsToHoldOutOrHalve) {
  CalibrationOptions options;
  options.holdout_views = 6;
  try {
    Calibrate(InputFromTruth(), options);
    FAIL() << "no throw";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("holdout: 6 views held out of 8 usable leave fewer than 3"), std::string::npos)
        << error.what();
  }
  options.holdout_views = -1;
  EXPECT_THROW(Calibrate(InputFromTruth(), options), InputError);
  // Views named to hold out: an image not in the set, and one whose 3 corners leave it
  // unusable, are both refused by name.
  options.holdout_views = 0;
  CalibrationInput input = InputFromTruth();
  input.detections->images[2].corners.resize(3);
  for (const std::string& name : {std::string("nowhere.png"), input.detections->images[2].image}) {
    options.holdout_images = {name};
    try {
      Calibrate(input, options);
      ADD_FAILURE() << name << ": no throw";
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find(name + ": not a usable view"), std::string::npos) << error.what();
    }
  }
}

}  // namespace
}  // namespace omnical

// Real images: C. Mei's paracatadioptric sample set in ../shared/real-data/mei-parabolic
// (read in place, never copied; the test skips where the folder is absent). The
// checkerboard is detected in every image and agrees with the 2007 reference corners, and
// the unknown-mirror mode (even polynomial, orthographic lens) calibrates all 10 views, also
// from the images scaled to 640 px and saved as JPEG.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <cmath>
#include <cstdio>
#include <map>
#include <mutex>
#include <set>
#include <sstream>

#include "calib/board_scale.h"
#include "calib/bundle_fit.h"
#include "calib/calibrate.h"
#include "calib/detect.h"
#include "calib/image_file.h"
#include "calib/initial_sensor.h"
#include "calib/rim_circle.h"
#include "model/io/codecs/image_codecs.h"
#include "test_sensors.h"

namespace omnical {
namespace {

const std::string kData = testing::SourceDir() + "/../shared/real-data/mei-parabolic";

// image name -> the reference corners' pixels (0-based pixel centres).
std::map<std::string, std::vector<Eigen::Vector2d>> ReferenceCorners() {
  std::map<std::string, std::vector<Eigen::Vector2d>> corners;
  std::ifstream file(kData + "/reference-corners-mei2007.csv");
  std::string line;
  while (std::getline(file, line)) {
    if (line.empty() || line[0] == '#' || line.rfind("image,", 0) == 0) continue;
    std::stringstream row(line);
    std::vector<std::string> fields;
    for (std::string field; std::getline(row, field, ',');) fields.push_back(field);
    corners[fields[0]].emplace_back(std::stod(fields[4]), std::stod(fields[5]));
  }
  return corners;
}

TEST(RealImages, MeiParabolicDetectsAndCalibrates) {
  if (!std::filesystem::exists(kData)) GTEST_SKIP() << kData << " is absent: the real-image test is skipped";
  const CalibrationTarget board = CalibrationTarget::FromYaml(testing::SourceDir() + "/tests/data/mei-parabolic-checkerboard.yaml");
  const auto reference = ReferenceCorners();
  DetectionSet detections;
  std::vector<double> distances;
  for (int k = 1; k <= 10; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "img_para_%03d.pgm", k);
    const cv::Mat grey = omnical::LoadImageFile(kData + "/" + name, cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(grey.empty()) << name;
    detections.image_width_px = grey.cols;
    detections.image_height_px = grey.rows;
    ImageDetections found = DetectTarget(board, grey);
    ASSERT_EQ(found.corners.size(), 48u) << name;
    // The reference of images 7 and 8 is itself off by up to 6 px (an overlay shows
    // omnical's corners on the X-junctions): compare on the other eight.
    if (k != 7 && k != 8)
      for (const CornerObservation& c : found.corners) {
        double nearest = HUGE_VAL;
        for (const Eigen::Vector2d& r : reference.at(name)) nearest = std::min(nearest, (c.pixel - r).norm());
        distances.push_back(nearest);
      }
    found.image = name;
    detections.images.push_back(found);
  }
  std::nth_element(distances.begin(), distances.begin() + distances.size() / 2, distances.end());
  // "Clicked, then refined": a few tenths of a pixel of disagreement (README of the data).
  EXPECT_LT(distances[distances.size() / 2], 0.4);

  // From the images alone: the rim circle, then the unknown-mirror polynomial (and the
  // paraboloid) with an orthographic lens, scale held.
  std::vector<RimCircle> circles;
  for (const ImageDetections& image : detections.images)
    if (auto circle = DetectRimCircle(omnical::LoadImageFile(kData + "/" + image.image, cv::IMREAD_GRAYSCALE))) circles.push_back(*circle);
  ASSERT_EQ(circles.size(), 10u);
  const RimCircle rim = *MedianRimCircle(circles);
  for (const auto& [profile, rms_bound] :
       std::vector<std::pair<std::string, double>>{{"polynomial", 0.45}, {"paraboloid", 1.3}}) {
    const Sensor guess = SensorFromRimCircle(rim, detections.image_width_px, detections.image_height_px, profile);
    std::vector<TargetPose> poses(detections.images.size());
    for (size_t v = 0; v < poses.size(); ++v) ASSERT_TRUE(InitialTargetPose(guess, board, detections.images[v], &poses[v])) << v;
    const FitResult fit = FitSensor(guess, board, detections, poses, FitOptions::DefaultsFor(guess));
    EXPECT_TRUE(fit.converged) << fit.solver_report;
    EXPECT_EQ(fit.dropped, 0);
    // Measured: polynomial 0.365 px over all 10 views (1 of 480 corners cut), paraboloid
    // 1.21 px (an ideal paraboloid cannot bend as the real mirror does: its misfit is the
    // bulk of the residuals, and the outlier rule's sigma counts it).
    EXPECT_LT(fit.rms_px, rms_bound) << profile;
    // Every view stays in the fit (the trust issue). The outlier rule (5 sigma of the
    // bulk, floor 0.5 px) cuts the polynomial's tail: measured 1 of 480 beyond 1.29 px (the
    // previous rule, 4 median sigma: 15, 3.1 %, beyond 0.84 px). The paraboloid's 37 beyond
    // 4.35 px are its misfit, not bad corners (not bounded).
    for (size_t v = 0; v < fit.view_left_out.size(); ++v) EXPECT_EQ(fit.view_left_out[v], "") << profile << " view " << v;
    if (profile == "polynomial") {
      EXPECT_LE(fit.outliers, 0.01 * 480);  // the issue's bound: at most 1 % cut
      // Real boards are the target's size: none is refused as another board.
      for (size_t v = 0; v < detections.images.size(); ++v) {
        const BoardScale check = CheckBoardScale(*fit.sensor, board, detections.images[v], fit.poses[v], fit.sigma_px);
        EXPECT_FALSE(check.refused) << detections.images[v].image << ": " << check.reason;
      }
    }
    std::printf("%s: RMS %.3f px, %d outliers beyond %.2f px\n", profile.c_str(), fit.rms_px, fit.outliers,
                fit.outlier_threshold_px);
    if (profile == "polynomial") {
      for (double view_rms : fit.per_view_rms_px) EXPECT_LT(view_rms, 0.7);
    }
    RecordProperty(profile + "_rms_px", std::to_string(fit.rms_px));
  }
  // The lens, chosen by held-out folds (calibrate's lens = auto, calib/lens_choice.h):
  // this sensor's lens is telecentric, and a perspective camera in front of the polynomial
  // mirror fits its corners about as well but predicts left-out views worse. Measured on
  // these corners (2026-11-29): orthographic 0.3838 px, pinhole 0.3995 px held out.
  // Then the mirror family (calib/profile_choice.h), by default without a guess: the even
  // asphere, a conic, fits this paraboloid's views no better than the polynomial (held out
  // 0.3818 px, 0.5 % lower, within the 1 % parsimony margin), and the polynomial is kept.
  CalibrationInput input;
  input.target = board;
  input.target_name = "mei-parabolic-checkerboard.yaml";
  input.detections = detections;
  for (ImageDetections& image : input.detections->images) image.image = kData + "/" + image.image;  // the rim circle reads them
  input.source = "detections";
  CalibrationOptions options;
  options.lens = kChooseLens;
  options.threads = 2;
  const CalibrationRecord chosen = Calibrate(input, options).record;
  ASSERT_TRUE(chosen.lens_choice.has_value());
  const NamedChoice& lens = *chosen.lens_choice;
  std::printf("lens choice: orthographic %.4f px, pinhole %.4f px held out\n", lens.held_out_rms_px[0], lens.held_out_rms_px[1]);
  EXPECT_EQ(lens.chosen, "orthographic");
  // ... then, through the orthographic lens, the spline's knot count or none: none here (a
  // manufactured paraboloid, which the polynomial describes; docs/calibrate.md).
  EXPECT_EQ(std::string(chosen.start),
            "rim circle, polynomial mirror (chosen by held-out folds), orthographic lens (chosen by held-out folds), "
            "no spline (chosen by held-out folds)");
  ASSERT_TRUE(chosen.knot_choice.has_value());
  EXPECT_EQ(chosen.knot_choice->chosen, 0);
  EXPECT_EQ(chosen.knot_choice->base_profile, "polynomial");
  // The pinhole is fitted and scored, not refused: the choice is by prediction.
  EXPECT_TRUE(std::isfinite(lens.held_out_rms_px[1]));
  EXPECT_GT(lens.held_out_rms_px[1], lens.held_out_rms_px[0]);
  ASSERT_TRUE(chosen.profile_choice.has_value());
  const NamedChoice& profile = *chosen.profile_choice;
  std::printf("mirror family: polynomial %.4f px, even asphere %.4f px held out\n", profile.held_out_rms_px[0],
              profile.held_out_rms_px[1]);
  EXPECT_EQ(profile.chosen, "polynomial");
  // The polynomial's score is the lens choice's (the same candidate, not fitted again); the
  // asphere's is fitted, and within 1 % of it (a 2 % gap would change the choice).
  EXPECT_EQ(profile.held_out_rms_px[0], lens.held_out_rms_px[0]);
  EXPECT_NEAR(profile.held_out_rms_px[1] / profile.held_out_rms_px[0], 1.0, 0.01);
  // Last, the board's relief (calib/relief_choice.h): this hand-held card has a shape the
  // paraboloid warp does not follow, which recurs in every view; learnt on the training
  // views it predicts the held-out ones better (measured on these corners 0.3838 -> 0.3635
  // px, 5 %; 0.3098 -> 0.2518 on the edge-refined ones), and it is fitted. The warp alone is
  // the family choice's candidate, its score reused.
  ASSERT_TRUE(chosen.relief_choice.has_value());
  const NamedChoice& relief = *chosen.relief_choice;
  EXPECT_EQ(relief.chosen, "warp+relief");
  EXPECT_EQ(relief.held_out_rms_px[0], profile.held_out_rms_px[0]);
  EXPECT_LT(relief.held_out_rms_px[1], 0.97 * relief.held_out_rms_px[0]);
  ASSERT_TRUE(chosen.board_warp.has_value());
  EXPECT_EQ(chosen.board_warp->warp.relief_mm.size(), 48u);
  // Determined by the corners, not by the relief's 1 mm prior (measured 0.20-0.34 mm; the
  // warp's 0.07 mm, against 0.39 before its paraboloids were held out of the relief).
  for (const auto& [id, std_mm] : chosen.board_warp->relief_std_mm) EXPECT_LT(std_mm, 0.5) << "corner " << id;
  EXPECT_LT(chosen.board_warp->std_x_mm, 0.2);
  EXPECT_LT(chosen.board_warp->std_y_mm, 0.2);
}

// The issue's bounds on the real dev set, calibrated as a user would (`omnical calibrate
// --images ... --board-warp --cross-validate --holdout-folds 2`), from the images alone:
// at most 1 % of the corners cut, the two halves within 0.35 px of each other at 2 m, and
// the held-out views' RMS within 25 % of the training views'. The held-out views are every
// view in turn (`--holdout-folds 2`: five more calibrations, each without two views),
// pooled. One split of two views is too few to judge by: over the five, the ratio of
// one split ran 0.78-1.62 with cornerSubPix corners (the default before) and 0.83-1.42 with
// the edge-refined ones (the default), pooled 1.07 and 1.09; the edge corners predicted 8
// of the 10 views better, pooled 0.345 -> 0.310 px, and the split of views 3 and 8 alone
// (the test's before) went 1.15 -> 1.42 because the training RMS fell more (0.320 -> 0.269)
// than view 8's bent board's (0.43 -> 0.46 px). Measured with the edge corners: 1 cut
// (0.2 %), halves 0.295 px, all-corner RMS 0.285 px (per corner; bounded here at 0.35 to
// catch a regression: mrcal's 10-knot spline fits the same corners at 0.239,
// docs/calibration-vs-mrcal.md). The halves bound holds on this (even/odd) split, not on
// every one (10 random 5/5 splits: median 0.312, up to 0.861 px with the cornerSubPix
// corners; tests/bench/mrcal_compare/random_splits.py). Every corner is refined through a
// fit without the held-out views (the first pass's), as the halves' through the full set's.
TEST(RealImages, MeiParabolicGeneralisesWithinTheIssuesBounds) {
  if (!std::filesystem::exists(kData)) GTEST_SKIP() << kData << " is absent: the real-image test is skipped";
  CalibrationInput input;
  input.target_name = testing::SourceDir() + "/tests/data/mei-parabolic-checkerboard.yaml";
  input.target = CalibrationTarget::FromYaml(input.target_name);
  input.image_paths = ListImages(kData);
  input.source = kData;
  CalibrationOptions options;
  options.board_warp = true;
  options.cross_validate = true;
  options.holdout_folds = 2;
  options.threads = 2;
  options.distances_mm = {2000.0};  // the predicted error where the halves are compared
  // Each choice's stage as it starts: (stage, jobs). The folds and the halves keep the full
  // set's lens and mirror family (one choosing again could judge another model than the
  // calibration written); the family's polynomial score is the lens choice's, reused: only
  // the even asphere is fitted, 5 folds. (The orthographic lens is chosen here: no
  // tangential terms to choose.)
  std::vector<std::pair<std::string, long>> choices;
  std::mutex mutex;
  options.progress = [&](const ProgressUpdate& update) {
    const std::lock_guard<std::mutex> lock(mutex);
    if (update.done == 0 && (update.stage == "lens" || update.stage == "profile" || update.stage == "tangential" ||
                             update.stage == "board relief"))
      choices.emplace_back(update.stage, update.total);
    return true;
  };
  const CalibrationResult full = Calibrate(input, options);
  const CalibrationRecord& record = full.record;
  EXPECT_EQ(choices, (std::vector<std::pair<std::string, long>>{{"lens", 10}, {"profile", 5}, {"board relief", 5}}));
  EXPECT_EQ(record.views_left_out.size(), 0u);
  EXPECT_EQ(record.observations, 480);
  EXPECT_LE(record.outliers, 0.01 * record.observations);
  // The issue's first bound: over all corners within mrcal's 10-knot splined model's 0.239
  // px on the same corners (docs/calibration-vs-mrcal.md; 0.241 on the corners as refined
  // through a fit with the relief), which the board's relief meets (measured 0.216 px;
  // 0.285 with the warp alone).
  ASSERT_TRUE(record.relief_choice.has_value());
  EXPECT_EQ(record.relief_choice->chosen, "warp+relief");
  EXPECT_LE(record.rms_all_px, 0.239);
  ASSERT_TRUE(record.cross_validation);
  EXPECT_DOUBLE_EQ(record.cross_validation->diff.distance_mm, 2000.0);
  EXPECT_LE(record.cross_validation->diff.rms_px, 0.35);
  // That bound is the issue's: the alignment fitted at 2 m itself, whose 16 mm translation
  // (the boards are at 0.2-0.45 m) takes up a zoom-like disagreement no pose could absorb.
  // With one alignment fitted at the boards' median distance, as the predicted error is
  // taken, the halves differ far more (measured 1.28 px RMS, 1.90 max), and the prediction
  // must cover that: each half has half the views, so the two differ by about 2 x the full
  // fit's predicted std (half the data: sqrt 2; the difference of two: sqrt 2 again); its
  // worst within 3 x that (measured 1.8 x, the predicted 0.53 px worst at 2 m: the paper
  // board's own bends are not in the model's noise).
  const auto& at_boards = record.cross_validation->diff_aligned_at_boards;
  ASSERT_TRUE(at_boards);
  ASSERT_EQ(record.predicted_error.size(), 1u);
  const CalibrationRecord::PredictedErrorSummary& at_2m = record.predicted_error[0];
  EXPECT_EQ(at_boards->aligned_at_mm, at_2m.aligned_at_mm);
  EXPECT_LT(at_boards->max_px, 3.0 * 2.0 * at_2m.max_px);
  RecordProperty("halves_at_2m_aligned_at_boards_rms_px", std::to_string(at_boards->rms_px));
  std::printf("halves at 2 m, one alignment at the boards' %.0f mm: %.3f px RMS, %.3f max; predicted (full set) worst "
              "%.3f px, median %.3f\n",
              at_boards->aligned_at_mm, at_boards->rms_px, at_boards->max_px, at_2m.max_px, at_2m.median_px);

  ASSERT_TRUE(record.holdout_folds);
  const HeldOutFolds& folds = *record.holdout_folds;
  ASSERT_EQ(folds.folds.size(), 5u);
  std::set<std::string> held_out_views;
  double held_square_px2 = 0.0;
  for (const HeldOutFolds::Fold& fold : folds.folds) {
    EXPECT_EQ(fold.corners, 96);
    EXPECT_EQ(fold.training_corners, 384);
    for (const std::string& view : fold.images) held_out_views.insert(view);
    held_square_px2 += fold.corners * fold.rms_px * fold.rms_px;
    std::printf("fold: held out %.3f px vs training %.3f px\n", fold.rms_px, fold.training_rms_px);
  }
  EXPECT_EQ(held_out_views.size(), 10u) << "every view held out once";
  EXPECT_EQ(folds.corners, 480);
  // The pooled figure is the folds' corners pooled, not another average.
  EXPECT_NEAR(folds.rms_px, std::sqrt(held_square_px2 / 480.0), 1e-12);
  EXPECT_LE(folds.rms_px, 1.25 * folds.training_rms_px)
      << "held out " << folds.rms_px << " px, training " << folds.training_rms_px << " px";
  std::printf("all-corner RMS %.3f px, %d cut, halves %.3f px at 2 m; every view held out: %.3f px vs training %.3f px\n",
              record.rms_all_px, record.outliers, record.cross_validation->diff.rms_px, folds.rms_px,
              folds.training_rms_px);
}

// The user the issue describes: the same sensor's images at 640 x 512 px and JPEG quality 75
// (area-averaged from 1280 x 1024), calibrated with the defaults from the images alone. Every
// board is used whole, img_para_002's too: it lies by the inner radius, where the first
// fit's virtual view showed its narrow margin only a quarter square out on two sides (half
// a square out read 112-144 against the squares' midpoint of 154) and the view was skipped
// ("no complete checkerboard") until the margin test looked there (calib/partial_checkerboard.cc).
// Measured: 480 corners, RMS 0.154 px (per corner; bounded at 0.25 to catch a regression:
// the full-size images fit at 0.275 px, these are half their scale).
TEST(RealImages, MeiParabolicAt640PxJpegKeepsEveryBoard) {
  if (!std::filesystem::exists(kData)) GTEST_SKIP() << kData << " is absent: the real-image test is skipped";
  CalibrationInput input;
  input.target_name = testing::SourceDir() + "/tests/data/mei-parabolic-checkerboard.yaml";
  input.target = CalibrationTarget::FromYaml(input.target_name);
  const std::filesystem::path directory = ::testing::TempDir() + "mei-640-jpeg";
  std::filesystem::remove_all(directory);
  std::filesystem::create_directories(directory);
  const auto write_jpeg = [&](const std::string& name, const cv::Mat& image) {
    std::vector<unsigned char> bytes;
    ASSERT_TRUE(EncodeImage(".jpg", image, &bytes, {cv::IMWRITE_JPEG_QUALITY, 75}));
    std::ofstream((directory / name).string(), std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  };
  for (const std::string& path : ListImages(kData)) {
    cv::Mat half;
    cv::resize(LoadImageFile(path, cv::IMREAD_GRAYSCALE), half, cv::Size(640, 512), 0, 0, cv::INTER_AREA);
    write_jpeg(std::filesystem::path(path).filename().replace_extension(".jpg").string(), half);
  }
  // Two images no view is made of, each named with the reason in the record: a frame
  // without a board, and one of another size.
  write_jpeg("no_board.jpg", cv::Mat(512, 640, CV_8UC1, cv::Scalar(90)));
  write_jpeg("other_size.jpg", cv::Mat(480, 640, CV_8UC1, cv::Scalar(90)));
  input.image_paths = ListImages(directory.string());
  input.source = directory.string();
  ASSERT_EQ(input.image_paths.size(), 12u);
  CalibrationOptions options;
  options.threads = 2;
  const CalibrationRecord record = Calibrate(input, options).record;
  std::filesystem::remove_all(directory);
  EXPECT_EQ(record.views_left_out.size(), 0u);
  EXPECT_EQ(record.poses.size(), 10u);
  EXPECT_EQ(record.observations, 480) << "every board whole";
  const std::map<std::string, std::string> skipped = {
      {(directory / "no_board.jpg").string(), "no complete checkerboard of 8 x 6 inner corners found"},
      {(directory / "other_size.jpg").string(), "its size differs from the first image's"}};
  EXPECT_EQ(record.views_skipped, skipped);
  EXPECT_LT(record.rms_px, 0.25);
  std::printf("640 px JPEG: %zu views, %d corners, RMS %.4f px\n", record.poses.size(), record.observations,
              record.rms_px);
}

}  // namespace
}  // namespace omnical

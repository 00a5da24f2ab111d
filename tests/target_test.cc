// Targets: Kalibr spec files load, the geometry and ids follow Kalibr's layout, and the
// printed aprilgrid decodes with the AprilTag detector to the right ids in the right places.
#include <gtest/gtest.h>

#include <apriltag/apriltag.h>
#include <apriltag/tag36h11.h>
#include <apriltag/tagStandard41h12.h>

#include <opencv2/imgcodecs.hpp>

#include <fstream>

#include "calib/target.h"
#include "model/input_error.h"
#include "model/io/codecs/image_codecs.h"
#include "test_sensors.h"

namespace omnical {
namespace {

TEST(Target, KalibrAprilGridGeometry) {
  const CalibrationTarget grid =
      CalibrationTarget::FromYaml(testing::SourceDir() + "/datasets-synthetic/targets/aprilgrid-6x6-88mm.yaml");
  ASSERT_EQ(grid.corners().size(), 144u);
  // Tag 7 = row 1, column 1; its corners counter-clockwise from bottom-left (Kalibr).
  const double pitch = 88.0 * 1.3;
  const TargetCorner& bottom_left = grid.corners()[4 * 7];
  EXPECT_EQ(bottom_left.id, 28);
  EXPECT_NEAR(bottom_left.point_in_target.x(), pitch, 1e-9);
  EXPECT_NEAR(bottom_left.point_in_target.y(), pitch, 1e-9);
  EXPECT_NEAR(grid.corners()[4 * 7 + 2].point_in_target.x(), pitch + 88.0, 1e-9);  // top-right
  EXPECT_NEAR(grid.corners()[4 * 7 + 2].point_in_target.y(), pitch + 88.0, 1e-9);
  EXPECT_NEAR(grid.max_mm().x() - grid.min_mm().x(), 6 * 88.0 + 5 * 0.3 * 88.0 + 2 * 0.3 * 88.0, 1e-9);
}

// Print at 100 dpi, detect with AprilTag 3: every tag, with the id printed at its place.
TEST(Target, PrintedAprilGridDecodesToItsIdsInPlace) {
  for (const char* family : {"tag36h11", "tagStandard41h12"}) {
    const CalibrationTarget grid =
        CalibrationTarget::AprilGrid(4, 3, 25.0, std::string(family) == "tag36h11" ? 0.3 : 1.0, family, 10);
    const std::string path = testing::PrivateTempDir() + "/grid.png";
    grid.WritePng(path, 100.0);
    cv::Mat image = omnical::LoadImageFile(path, cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(image.empty());
    image_u8_t frame{image.cols, image.rows, static_cast<int32_t>(image.step), image.data};
    apriltag_family_t* fam = std::string(family) == "tag36h11" ? tag36h11_create() : tagStandard41h12_create();
    apriltag_detector_t* detector = apriltag_detector_create();
    apriltag_detector_add_family(detector, fam);
    zarray_t* detections = apriltag_detector_detect(detector, &frame);
    const double px_per_mm = 100.0 / 25.4;
    int found = 0;
    for (int i = 0; i < zarray_size(detections); ++i) {
      apriltag_detection_t* d;
      zarray_get(detections, i, &d);
      const int index = d->id - 10;
      ASSERT_GE(index, 0);
      ASSERT_LT(index, 12);
      // The tag's centre in the print, from the board geometry (y up -> image rows down).
      const Eigen::Vector3d& bl = grid.corners()[4 * index].point_in_target;
      const double cx = (bl.x() + 12.5 - grid.min_mm().x()) * px_per_mm - 0.5;
      const double cy = (grid.max_mm().y() - (bl.y() + 12.5)) * px_per_mm - 0.5;
      EXPECT_NEAR(d->c[0], cx, 1.0) << family << " id " << d->id;
      EXPECT_NEAR(d->c[1], cy, 1.0) << family << " id " << d->id;
      ++found;
    }
    EXPECT_EQ(found, 12) << family;
    apriltag_detections_destroy(detections);
    apriltag_detector_destroy(detector);
    if (std::string(family) == "tag36h11") tag36h11_destroy(fam); else tagStandard41h12_destroy(fam);
  }
}

TEST(Target, BadSpecsAreRejectedWithTheField) {
  struct Case {
    const char* text;
    const char* expected;
  };
  const Case cases[] = {
      {"target_type: aprilgrid\ntagCols: 6\ntagRows: 6\ntagSize: 0\ntagSpacing: 0.3\n", "tagSize: must be > 0"},
      {"target_type: aprilgrid\ntagCols: 6\ntagRows: 6\ntagSize: 0.03\ntagSpacing: 0.3\ntagFamily: tag99\n",
       "tagFamily: unknown tag family 'tag99'"},
      {"target_type: aprilgrid\ntagCols: 6\ntagRows: 6\ntagSize: 0.03\ntagSpacing: 0.3\ntagFamily: tagStandard41h12\n",
       "tagSpacing: 0.3 is too small for tagStandard41h12"},
      {"target_type: aprilgrid\ntagCols: 60\ntagRows: 60\ntagSize: 0.03\ntagSpacing: 0.3\n", "exceed the 587 codes"},
      {"target_type: circles\n", "target_type: unknown target type 'circles'"},
      {"target_type: checkerboard\ntargetCols: 8\ntargetRows: 6\nrowSpacingMeters: 0.03\n", "colSpacingMeters: missing"},
      {"target_type: checkerboard\ntargetCols: 8.5\ntargetRows: 6\nrowSpacingMeters: 0.03\ncolSpacingMeters: 0.03\n",
       "targetCols: must be a whole number"},
  };
  for (const Case& c : cases) {
    const std::string path = testing::PrivateTempDir() + "/bad_target.yaml";
    std::ofstream(path) << c.text;
    try {
      CalibrationTarget::FromYaml(path);
      ADD_FAILURE() << "no error for: " << c.text;
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find(c.expected), std::string::npos) << error.what();
      EXPECT_EQ(std::string(error.what()).rfind(path, 0), 0u) << error.what();
    }
  }
}

}  // namespace
}  // namespace omnical

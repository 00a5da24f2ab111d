// The fuzzers' reproducers (tests/data/fuzz-crashes) through the readers they crashed:
// each file is refused with an InputError naming it. Apart from sensor_yaml_test because
// the scene, detections and target readers live above omnical::formats.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "calib/detections.h"
#include "calib/synthetic/scene.h"
#include "calib/target.h"
#include "model/input_error.h"
#include "model/io/sensor_yaml.h"
#include "test_sensors.h"

namespace omnical {
namespace {

// Regression (tests/fuzz, scene_yaml): a scene naming a directory as its sensor ("sensor:
// ..") let std::ios_failure out of yaml-cpp, "internal error" in the CLI. The fuzzer's
// reproducer is kept in tests/data/fuzz-crashes; a directory given directly to the sensor
// and detections readers is refused the same way.
TEST(FuzzReproducers, ADirectoryWhereAFileBelongsIsRefused) {
  const std::string crashes = testing::SourceDir() + "/tests/data/fuzz-crashes";
  try {
    LoadSceneYaml(crashes + "/scene_yaml-sensor-is-a-directory.yaml");
    ADD_FAILURE() << "scene accepted";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("is a directory"), std::string::npos) << error.what();
  }
  EXPECT_THROW(LoadSensorYaml(crashes), InputError);
  EXPECT_THROW(ReadDetections(crashes), InputError);
}

// Regression (tests/fuzz, design_spec_yaml): the 3-byte file "? :" (a map whose key is a
// null complex key) let yaml-cpp's bad-conversion exception out of every YAML reader's
// unknown-field check.
TEST(FuzzReproducers, AComplexKeyIsRefused) {
  const std::string reproducer = testing::SourceDir() + "/tests/data/fuzz-crashes/design_spec_yaml-complex-key.yaml";
  for (auto load : {+[](const std::string& path) { LoadSensorYaml(path); },
                    +[](const std::string& path) { LoadSceneYaml(path); },
                    +[](const std::string& path) { CalibrationTarget::FromYaml(path); }}) {
    try {
      load(reproducer);
      ADD_FAILURE() << "accepted";
    } catch (const InputError& error) {
      // The readers check different fields first; each names the file.
      EXPECT_NE(std::string(error.what()).find("complex-key.yaml"), std::string::npos) << error.what();
    }
  }
}

// Regression (tests/fuzz, scene_yaml): "seed: -1" (and seeds past 2^32 - 1 or with a
// fraction) was cast to unsigned, undefined behaviour; both seeds of a scene are refused.
TEST(FuzzReproducers, ASeedOutsideTheGeneratorsRangeIsRefused) {
  const std::string reproducer = testing::SourceDir() + "/tests/data/fuzz-crashes/scene_yaml-negative-seed.yaml";
  try {
    LoadSceneYaml(reproducer);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("negative-seed.yaml: render.seed: must be a whole number"), std::string::npos)
        << error.what();
  }
  const std::string sensor = testing::SourceDir() + "/datasets-synthetic/sensors/ohte-sph.yaml";
  const std::string target = testing::SourceDir() + "/datasets-synthetic/targets/aprilgrid-6x6-30mm.yaml";
  for (const char* seed : {"-1", "4294967296", "2.5", "1e300"}) {
    const std::string path = testing::PrivateTempDir() + "/random_seed.yaml";
    std::ofstream(path) << "sensor: " << sensor << "\ntargets: { board: " << target
                        << " }\nrandom_views: { count: 1, target: board, seed: " << seed << " }\n";
    try {
      LoadSceneYaml(path);
      ADD_FAILURE() << "seed " << seed << " accepted";
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find("random_views.seed: must be a whole number"), std::string::npos)
          << error.what();
    }
  }
}

// Regression (fuzzing by hand, 2026-11-25): ids were read with truncation (2.5 -> 2, 2^40
// and 2^64 - 1 wrapped, true -> 1), and a corner at 1e300 px overflowed the report's
// histogram (a segfault). Whole numbers written as floats (numpy's tolist()) are ids.
TEST(FuzzReproducers, DetectionsWithOddIdsOrFarPixelsAreRefused) {
  const std::string path = ::testing::TempDir() + "/odd-detections.json";
  auto read_with = [&](const std::string& id, const std::string& pixel) {
    std::ofstream(path) << R"({"target": "t.yaml", "image_size": [100, 80], "images": [{"image": "a.png", "corners": [)"
                        << R"({"id": )" << id << R"(, "pixel": )" << pixel << "}]}]}";
    try {
      const DetectionSet set = ReadDetections(path);
      return "id " + std::to_string(set.images.at(0).corners.at(0).id);
    } catch (const InputError& error) {
      return std::string(error.what());
    }
  };
  const std::string not_whole = path + ": images[0] (a.png).id: must be a whole number of at most 10 digits (got ";
  EXPECT_EQ(read_with("2.5", "[1, 2]"), not_whole + "2.5)");
  EXPECT_EQ(read_with("true", "[1, 2]"), not_whole + "true)");
  EXPECT_EQ(read_with("1099511627776", "[1, 2]"), not_whole + "1099511627776)");
  EXPECT_EQ(read_with("18446744073709551615", "[1, 2]"), not_whole + "18446744073709551615)");
  EXPECT_EQ(read_with("3.0", "[1, 2]"), "id 3");
  EXPECT_EQ(read_with("-1", "[1, 2]"), "id -1");  // an id the target lacks: dropped by the fit, not here
  EXPECT_EQ(read_with("3", "[1e300, 2]"), path + ": images[0] (a.png): corner 3's pixel (1e+300, 2) lies far outside the 100 x 80 image");
  EXPECT_EQ(read_with("3", "[-100, 2]"), "id 3");  // exactly an image size outside: the bound itself
  EXPECT_EQ(read_with("3", "[1, 2, 3]"), path + ": images[0] (a.png): corner 3's pixel must be [u, v]");
}

}  // namespace
}  // namespace omnical

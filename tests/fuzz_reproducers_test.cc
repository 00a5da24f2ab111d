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

}  // namespace
}  // namespace omnical

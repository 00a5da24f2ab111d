// libFuzzer entry for every parser of a user file (issue 8), one binary; the environment
// variable OMNICAL_FUZZ_TARGET picks the parser (scripts/fuzz.sh runs each in turn):
//   sensor_yaml scene_yaml target_yaml design_spec_yaml detections_json maps_json
//   maps_yml points_csv profile_csv
// The input is written to a file the parser reads, as the CLI does. A parser may refuse
// the input only with InputError; any other exception escapes, and libFuzzer reports it
// as a crash (the CLI would answer it with "internal error", exit 1). ASan and UBSan are
// compiled in (OMNICAL_FUZZ), so memory errors and undefined behaviour are crashes too.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "calib/detections.h"
#include "calib/target.h"
#include "correction/map_export.h"
#include "calib/synthetic/scene.h"
#include "correction/maps_json.h"
#include "model/io/csv_reader.h"
#include "model/design/design_spec_yaml.h"
#include "model/input_error.h"
#include "model/io/profile_table.h"
#include "model/sensor.h"
#include "model/tabulated_profile.h"
#include "model/io/sensor_yaml.h"

namespace {

namespace fs = std::filesystem;

// A private directory per process. A scene names its sensor and targets relative to
// itself (../sensors/x.yaml): links to datasets-synthetic's folders beside the input let
// the seed corpus reach past that first step.
const fs::path& WorkDir() {
  static const fs::path dir = [] {
    const fs::path d = fs::temp_directory_path() / ("omnical-fuzz-" + std::to_string(getpid()));
    fs::create_directories(d / "in");
    if (const char* data = std::getenv("OMNICAL_FUZZ_DATA")) {
      for (const char* sub : {"sensors", "targets", "designs"}) {
        std::error_code ignored;
        fs::create_directory_symlink(fs::path(data) / sub, d / sub, ignored);
      }
    }
    return d;
  }();
  return dir;
}

std::string WriteInput(const uint8_t* data, size_t size, const std::string& name) {
  const fs::path path = WorkDir() / "in" / name;
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path.string();
}

void RunTarget(const std::string& target, const uint8_t* data, size_t size) {
  using namespace omnical;
  if (target == "sensor_yaml") {
    const Sensor sensor = LoadSensorYaml(WriteInput(data, size, "sensor.yaml"));
    // A sensor that loads must also project without trouble.
    Eigen::Vector2d pixel;
    sensor.Project(Eigen::Vector3d(300.0, 40.0, 100.0), &pixel);
    Eigen::Vector3d origin, direction;
    sensor.Unproject(Eigen::Vector2d(0.3 * sensor.image_width_px(), 0.5 * sensor.image_height_px()), &origin, &direction);
  } else if (target == "scene_yaml") {
    LoadSceneYaml(WriteInput(data, size, "scene.yaml"));
  } else if (target == "target_yaml") {
    CalibrationTarget::FromYaml(WriteInput(data, size, "target.yaml"));
  } else if (target == "design_spec_yaml") {
    LoadOdeDesignSpec(WriteInput(data, size, "design.yaml"));
  } else if (target == "detections_json") {
    ReadDetections(WriteInput(data, size, "detections.json"));
  } else if (target == "maps_json") {
    WriteInput(data, size, "maps.json");
    ReadMapsDescription((WorkDir() / "in").string(), nullptr);
  } else if (target == "maps_yml") {
    ReadOpenCvMaps(WriteInput(data, size, "maps.yml"));
  } else if (target == "points_csv") {
    ReadNumericCsv(WriteInput(data, size, "points.csv"), 3);
  } else if (target == "profile_csv") {
    LoadProfileTable(WriteInput(data, size, "profile.csv"));
  } else {
    std::fprintf(stderr, "OMNICAL_FUZZ_TARGET: unknown or unset ('%s')\n", target.c_str());
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string target = std::getenv("OMNICAL_FUZZ_TARGET") ? std::getenv("OMNICAL_FUZZ_TARGET") : "";
  try {
    RunTarget(target, data, size);
  } catch (const omnical::InputError&) {
    // The expected answer to bad input.
  }
  return 0;
}

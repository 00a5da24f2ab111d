// Calibrating a sensor from C++: the target spec, the images and a design guess in, a
// fitted sensor and the calibration record out (what `omnical calibrate` writes as
// sensor.yaml and calibration.json). With a calibration.json from the CLI as a fourth
// argument, every number of the two records must agree to 1e-9 (relative).
// Usage: calibrate_set TARGET.yaml IMAGE_DIR GUESS.yaml [CLI_CALIBRATION.json]
#include <cmath>
#include <cstdio>
#include <string>

#include "calib/calibrate.h"
#include "calib/calibration_json.h"
#include "calib/image_file.h"
#include "model/input_error.h"
#include "model/io/sensor_yaml.h"

namespace {

bool Close(double a, double b) { return a == b || std::abs(a - b) <= 1e-9 * std::max(1.0, std::abs(a)); }

int Compare(const omnical::CalibrationRecord& mine, const omnical::CalibrationRecord& cli) {
  int differ = 0;
  auto check = [&](const std::string& what, double a, double b) {
    if (Close(a, b)) return;
    std::printf("differs: %s %.17g vs %.17g\n", what.c_str(), a, b);
    ++differ;
  };
  check("rms_px", mine.rms_px, cli.rms_px);
  check("observations", mine.observations, cli.observations);
  if (mine.parameters.size() != cli.parameters.size()) return 1;
  for (const omnical::ParameterEstimate& p : mine.parameters)
    for (const omnical::ParameterEstimate& q : cli.parameters)
      if (p.name == q.name) check(p.name, p.value, q.value), check(p.name + " std", p.std, q.std);
  for (const auto& [image, pose] : mine.poses) {
    const auto other = cli.poses.find(image);
    if (other == cli.poses.end()) return 1;
    for (int k = 0; k < 3; ++k)
      check(image + " translation", pose.camera_from_target_translation_mm[k], other->second.camera_from_target_translation_mm[k]);
  }
  return differ;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) return 2;
  try {
    omnical::CalibrationInput input;
    input.target_name = argv[1];
    input.target = omnical::CalibrationTarget::FromYaml(argv[1]);
    input.image_paths = omnical::ListImages(argv[2]);
    input.source = argv[2];
    input.guess_name = argv[3];
    input.guess = omnical::LoadSensorYaml(argv[3]);
    input.guess_tolerances = omnical::ReadDesignTolerances(argv[3], *input.guess);
    omnical::CalibrationOptions options;
    options.threads = 2;
    options.progress = [](const omnical::ProgressUpdate& update) {
      if (update.done == update.total) std::printf("%s: done\n", update.stage.c_str());
      return true;  // false would cancel (omnical::Cancelled)
    };
    const omnical::CalibrationResult result = omnical::Calibrate(input, options);
    std::printf("%zu views, RMS %.4f px (per corner)\n", result.views.images.size(), result.record.rms_px);
    for (const omnical::CalibrationWarning& warning : result.warnings) std::printf("warning: %s\n", warning.text.c_str());
    if (argc < 5) return 0;
    const int differ = Compare(result.record, omnical::ReadCalibrationJson(argv[4]));
    std::printf("%s\n", differ ? "differs from the CLI's calibration.json" : "same as the CLI's calibration.json (1e-9)");
    return differ ? 1 : 0;
  } catch (const omnical::InputError& error) {
    std::printf("error: %s\n", error.what());
    return 2;
  }
}

// A synthetic scene for `omnical render`: a sensor, planar targets placed around it per
// view, an environment, and the image formation settings (YAML, see docs/file-formats.md "Scene file").
//
// Target placement (mirror frame): the board centre sits at distance_mm from the mirror
// vertex in the direction (Omega, azimuth) of the seed paper (Omega from the -z axis), its
// printed face turned towards the vertex, then rolled about its normal and tilted about
// its own x and y axes.
#pragma once

#include <Eigen/Core>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "calib/board_warp.h"
#include "calib/target.h"
#include "model/sensor.h"

namespace omnical {

struct Environment {
  enum class Type { kGrey, kRoom } type = Type::kRoom;
  double level = 0.5;             // grey
  double half_size_mm = 3000.0;   // room: a cube around the sensor
  double tile_mm = 300.0;         // room: checker tiles on its walls
  double low = 0.25, high = 0.55;  // room: the two tile reflectances
  // room: tiles on every face, or only on the floor and ceiling (the faces across the
  // camera's z axis, the mirror's axis) with plain walls at the tiles' mean level.
  bool tiled_walls = true;
};

struct ImageFormation {
  int samples_per_pixel = 16;  // a perfect square: n x n stratified samples
  double noise_sigma = 0.0;    // Gaussian sensor noise, grey levels of 255
  double blur_sigma_px = 0.0;  // defocus, Gaussian
  double vignetting = 0.0;     // brightness x (1 - vignetting (r / r_rim)^2)
  int jpeg_quality = 0;        // 0: PNG (lossless); 1-100: the images are written as JPEG of that quality
  bool colour = false;         // 3 channels with a warm white balance (per-channel gains) and per-channel noise
  unsigned seed = 1;
};

struct PlacedTarget {
  std::string name;
  std::shared_ptr<const CalibrationTarget> target;
  std::string spec_path;
  Eigen::Matrix3d camera_from_target_rotation;
  Eigen::Vector3d camera_from_target_translation_mm;
  WarpedSurface surface;  // the board's bend (calib/board_warp.h); flat when its warp is zero
};

struct SceneView {
  std::string name;
  std::vector<PlacedTarget> targets;
};

struct Scene {
  std::string path;
  std::optional<Sensor> sensor;
  Environment environment;
  ImageFormation formation;
  std::vector<SceneView> views;
};

// Throws InputError "scene.yaml: field: problem" (unreadable file, unknown keys, missing
// target spec, a target that is not visible in the mirror, ...).
Scene LoadSceneYaml(const std::string& path);

// Places a board as described above (angles in degrees). Exposed for tests.
void PlaceTarget(const Sensor& sensor, const CalibrationTarget& target, double omega_deg, double azimuth_deg,
                 double distance_mm, double roll_deg, double tilt_x_deg, double tilt_y_deg,
                 Eigen::Matrix3d* camera_from_target_rotation, Eigen::Vector3d* camera_from_target_translation_mm);

}  // namespace omnical

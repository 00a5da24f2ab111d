// Detected target corners per image: what `omnical detect` writes and `omnical
// calibrate` reads (JSON). A rendered view's ground truth converts to the same form
// (calib/synthetic/ground_truth.h).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace omnical {

struct CornerObservation {
  int id;                 // the target's corner id (calib/target.h)
  Eigen::Vector2d pixel;  // u = column, v = row; pixel (0, 0) has its centre at (0, 0)
  // Sub-pixel refinement through a sensor guess failed (occluded edge, cut by the rim, a
  // neighbour missing): the detector's own position, 0.1-9 px off on renders instead of
  // ~0.05. Kept so the detection is not lost; `omnical calibrate` leaves it out of the fit.
  bool unrefined = false;
  // Placed by a prediction, not by a detector (calib/checkerboard_completion.h): dropped
  // unless its refinement succeeds.
  bool predicted = false;
};

struct ImageDetections {
  std::string image;  // path as given to detect
  std::vector<CornerObservation> corners;
};

struct DetectionSet {
  std::string target_spec;  // the spec file the ids refer to
  int image_width_px = 0, image_height_px = 0;
  std::vector<ImageDetections> images;
  std::string target_description;  // CalibrationTarget::Describe() of it ("" in files from before it was written)
};

// JSON: {"target": spec, "image_size": [W, H], "images": [{"image": path,
// "corners": [{"id": i, "pixel": [u, v]}, ...]}, ...]}; an unrefined corner also has
// "refined": false, one placed by a prediction through a fit and confirmed by its
// refinement "predicted": true; "target_description" (optional) describes the board the
// corners were found on (CalibrationTarget::Describe). Read throws InputError naming the
// file and the entry; write is atomic.
DetectionSet ReadDetections(const std::string& path);
void WriteDetections(const DetectionSet& detections, const std::string& path);

}  // namespace omnical

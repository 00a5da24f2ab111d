// A rendered view's ground truth (<view>.json beside <view>.png): written by the render
// job, read back as the detections a perfect detector would give.
// JSON: {"view", "image", "image_size": [W, H], "sensor_file", "sensor_yaml",
// "pixel_convention", "targets": [{"name", "spec" (relative to the file), "type",
// "camera_from_target": {"rotation" (3x3 rows), "translation_mm"}, "warp_mm" (the board's
// bend, calib/board_warp.h; target_mm then lies on the bent surface), "corners": [{"id",
// "target_mm", "camera_mm", "pixel" ([u, v] or null), "status", "visible"}],
// "visible_corners"}]}.
#pragma once

#include <string>
#include <vector>

#include "calib/detections.h"
#include "calib/synthetic/renderer.h"

namespace omnical {

// The ground-truth text of one view; spec paths are written relative to `out_dir`, so a
// rendered set moves with its repository.
std::string GroundTruthJsonText(const SceneView& view, const std::vector<TargetTruth>& truth, const std::string& out_dir,
                                const std::string& sensor_yaml, const Sensor& sensor, const std::string& image_file);

// The image file a view is written to: <view>.png, or <view>.jpg when the scene renders JPEG.
std::string RenderedImageName(const SceneView& view, const ImageFormation& formation);

// The visible corners of rendered views (their <view>.json files). Throws InputError
// naming the file.
DetectionSet DetectionsFromGroundTruth(const std::vector<std::string>& truth_paths);

}  // namespace omnical

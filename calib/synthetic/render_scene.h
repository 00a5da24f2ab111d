// Rendering a scene's views with their ground truth: in memory first, written together at
// the end, so an interrupted render leaves the previous set whole (never new images beside
// old ground truth).
#pragma once

#include <opencv2/core.hpp>

#include <string>
#include <vector>

#include "calib/synthetic/renderer.h"
#include "calib/synthetic/scene.h"
#include "model/progress.h"

namespace omnical {

struct RenderOptions {
  int threads = 1;
  ProgressCallback progress;  // stage "render <view> (k/N)", rows of the image
  std::string Check() const;  // "" or "field: problem"
};

struct RenderedView {
  const SceneView* view;  // into the scene rendered
  cv::Mat image;          // 8-bit grey, or BGR (ImageFormation::colour)
  std::vector<TargetTruth> truth;
};

// Throws Cancelled (between views) when the callback asks to stop.
std::vector<RenderedView> RenderScene(const Scene& scene, const RenderOptions& options);

// DIR/<view>.png, DIR/<view>.json (calib/synthetic/ground_truth.h), DIR/sensor.yaml and
// DIR/scene.json (the index: the scene file relative to DIR, the views' files), each
// atomically; `scene_path` is the scene file the index names.
void WriteRenderedScene(const Scene& scene, const std::string& scene_path, const std::vector<RenderedView>& views,
                        const std::string& dir);

}  // namespace omnical

// omnical render: ray-trace the views of a scene through the exact sensor model, with
// ground truth for every target corner (calib/synthetic/render_scene.h): DIR/<view>.png,
// DIR/<view>.json, DIR/sensor.yaml, DIR/scene.json.
#include <chrono>
#include <thread>

#include "calib/synthetic/render_scene.h"
#include "model/io/atomic_write.h"
#include "tools/commands.h"
#include "tools/progress.h"

namespace omnical::cli {

Command RenderCommand() {
  return {"render", "Ray-trace a scene's views through the mirror, with ground truth for every target corner",
          [](CLI::App& sub, const Context& context) -> CommandAction {
            auto scene_path = std::make_shared<std::string>();
            auto out_dir = std::make_shared<std::string>();
            auto options = std::make_shared<RenderOptions>();
            options->threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
            sub.add_option("--scene", *scene_path, "Scene file (YAML)")->required();
            sub.add_option("--out", *out_dir, "Output directory")->required();
            sub.add_option("--threads", options->threads, "Worker threads")->check(CLI::Range(1, 256))->capture_default_str();
            return [=, &context]() {
              const Scene scene = LoadSceneYaml(*scene_path);
              CreateOutputDirectory(*out_dir);
              const auto start = std::chrono::steady_clock::now();
              options->progress = TerminalProgress(context);
              const std::vector<RenderedView> views = RenderScene(scene, *options);
              WriteRenderedScene(scene, *scene_path, views, *out_dir);
              if (context.quiet) return;
              const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
              const Sensor& sensor = *scene.sensor;
              std::printf("%s: %zu views, %d x %d px, %d samples per pixel, %.2f s -> %s\n", scene_path->c_str(),
                          scene.views.size(), sensor.image_width_px(), sensor.image_height_px(),
                          scene.formation.samples_per_pixel, seconds, out_dir->c_str());
            };
          }};
}

}  // namespace omnical::cli

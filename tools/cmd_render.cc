// omnical render: ray-trace the views of a scene through the exact sensor model, with
// ground truth for every target corner (DIR/<view>.png, DIR/<view>.json, DIR/sensor.yaml,
// DIR/scene.json).
#include <nlohmann/json.hpp>

#include <opencv2/imgcodecs.hpp>

#include <chrono>
#include <filesystem>
#include <thread>

#include "correction/renderer.h"
#include "model/atomic_write.h"
#include "model/input_error.h"
#include "tools/commands.h"
#include "tools/progress.h"

namespace omnical::cli {
namespace {

nlohmann::json TruthJson(const SceneView& view, const std::vector<TargetTruth>& truth, const std::string& out_dir, const std::string& sensor_yaml,
                         const Sensor& sensor) {
  nlohmann::json out;
  out["view"] = view.name;
  out["image"] = view.name + ".png";
  out["image_size"] = {sensor.image_width_px(), sensor.image_height_px()};
  out["sensor_file"] = "sensor.yaml";
  out["sensor_yaml"] = sensor_yaml;
  out["pixel_convention"] = "u = column, v = row; the centre of pixel (0, 0) is at (0, 0)";
  for (const TargetTruth& target : truth) {
    const PlacedTarget& placed = *target.placement;
    nlohmann::json t;
    t["name"] = placed.name;
    // Relative to the output directory, so a rendered set moves with its repository.
    t["spec"] = std::filesystem::proximate(std::filesystem::absolute(placed.spec_path), std::filesystem::absolute(out_dir)).string();
    t["type"] = placed.target->type() == CalibrationTarget::Type::kAprilGrid ? "aprilgrid" : "checkerboard";
    nlohmann::json rotation = nlohmann::json::array();
    for (int r = 0; r < 3; ++r)
      rotation.push_back({placed.camera_from_target_rotation(r, 0), placed.camera_from_target_rotation(r, 1),
                          placed.camera_from_target_rotation(r, 2)});
    t["camera_from_target"] = {{"rotation", rotation},
                               {"translation_mm",
                                {placed.camera_from_target_translation_mm.x(), placed.camera_from_target_translation_mm.y(),
                                 placed.camera_from_target_translation_mm.z()}}};
    int visible = 0;
    for (const CornerTruth& c : target.corners) {
      nlohmann::json corner;
      corner["id"] = c.id;
      corner["target_mm"] = {c.point_in_target_mm.x(), c.point_in_target_mm.y(), c.point_in_target_mm.z()};
      corner["camera_mm"] = {c.point_in_camera_mm.x(), c.point_in_camera_mm.y(), c.point_in_camera_mm.z()};
      corner["pixel"] = c.status == ProjectionStatus::kOk ? nlohmann::json({c.pixel.x(), c.pixel.y()}) : nlohmann::json(nullptr);
      corner["status"] = StatusName(c.status);
      corner["visible"] = c.visible;
      visible += c.visible;
      t["corners"].push_back(corner);
    }
    t["visible_corners"] = visible;
    out["targets"].push_back(t);
  }
  return out;
}

}  // namespace

Command RenderCommand() {
  return {"render", "Ray-trace a scene's views through the mirror, with ground truth for every target corner",
          [](CLI::App& sub, const Context& context) -> CommandAction {
            auto scene_path = std::make_shared<std::string>();
            auto out_dir = std::make_shared<std::string>();
            auto threads = std::make_shared<int>(static_cast<int>(std::max(1u, std::thread::hardware_concurrency())));
            sub.add_option("--scene", *scene_path, "Scene file (YAML)")->required();
            sub.add_option("--out", *out_dir, "Output directory")->required();
            sub.add_option("--threads", *threads, "Worker threads")->check(CLI::Range(1, 256))->capture_default_str();
            return [=, &context]() {
              const Scene scene = LoadSceneYaml(*scene_path);
              const Sensor& sensor = *scene.sensor;
              CreateOutputDirectory(*out_dir);
              const std::filesystem::path dir(*out_dir);
              const std::string sensor_yaml = SensorYamlText(sensor);
              const auto start = std::chrono::steady_clock::now();
              const PixelRayGrid rays(sensor, *threads);
              nlohmann::json index;
              index["scene"] = std::filesystem::proximate(std::filesystem::absolute(*scene_path), std::filesystem::absolute(dir)).string();
              index["sensor_file"] = "sensor.yaml";
              struct RenderedView {
                std::vector<uchar> png;
                std::string truth;
              };
              std::vector<RenderedView> rendered;
              for (size_t k = 0; k < scene.views.size(); ++k) {
                const SceneView& view = scene.views[k];
                cv::Mat image;
                {
                  Progress progress("render " + view.name + " (" + std::to_string(k + 1) + "/" +
                                        std::to_string(scene.views.size()) + ")",
                                    sensor.image_height_px(), context.quiet);
                  image = RenderView(sensor, rays, view, scene.environment, scene.formation, static_cast<unsigned>(k),
                                     *threads, [&](long rows) { progress.Advance(rows); });
                }
                // Kept in memory and written together at the end: an interrupted render
                // leaves the previous set whole, never new images beside old ground truth.
                rendered.emplace_back();
                cv::imencode(".png", image, rendered.back().png, {cv::IMWRITE_PNG_COMPRESSION, 9});
                rendered.back().truth =
                    TruthJson(view, GroundTruth(sensor, view), *out_dir, sensor_yaml, sensor).dump(1) + '\n';
                index["views"].push_back({{"name", view.name}, {"image", view.name + ".png"}, {"truth", view.name + ".json"}});
              }
              for (size_t k = 0; k < scene.views.size(); ++k) {
                const std::vector<uchar>& png = rendered[k].png;
                WriteFileAtomically((dir / (scene.views[k].name + ".png")).string(), [&](std::ostream& out) {
                  out.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
                });
                WriteFileAtomically((dir / (scene.views[k].name + ".json")).string(),
                                    [&](std::ostream& out) { out << rendered[k].truth; });
              }
              WriteFileAtomically((dir / "sensor.yaml").string(), [&](std::ostream& out) { out << sensor_yaml; });
              WriteFileAtomically((dir / "scene.json").string(), [&](std::ostream& out) { out << index.dump(2) << '\n'; });
              if (!context.quiet) {
                const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
                std::printf("%s: %zu views, %d x %d px, %d samples per pixel, %.2f s -> %s\n", scene_path->c_str(),
                            scene.views.size(), sensor.image_width_px(), sensor.image_height_px(),
                            scene.formation.samples_per_pixel, seconds, out_dir->c_str());
              }
            };
          }};
}

}  // namespace omnical::cli

#include "calib/synthetic/ground_truth.h"

#include <nlohmann/json.hpp>

#include <filesystem>

#include "model/input_error.h"
#include "model/io/json_file.h"

namespace omnical {

std::string GroundTruthJsonText(const SceneView& view, const std::vector<TargetTruth>& truth, const std::string& out_dir,
                                const std::string& sensor_yaml, const Sensor& sensor, const std::string& image_file) {
  nlohmann::json out;
  out["view"] = view.name;
  out["image"] = image_file;
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
    t["warp_mm"] = {placed.surface.warp.x_mm, placed.surface.warp.y_mm};
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
  return out.dump(1) + '\n';
}


std::string RenderedImageName(const SceneView& view, const ImageFormation& formation) {
  return view.name + (formation.jpeg_quality > 0 ? ".jpg" : ".png");
}

DetectionSet DetectionsFromGroundTruth(const std::vector<std::string>& truth_paths) {
  DetectionSet set;
  for (const std::string& path : truth_paths) {
    const nlohmann::json json = ReadJsonFile(path);
    try {
      set.image_width_px = json.at("image_size").at(0).get<int>();
      set.image_height_px = json.at("image_size").at(1).get<int>();
      for (const nlohmann::json& target : json.at("targets")) {
        // A relative spec is relative to the ground-truth file (omnical render writes it so).
        const std::filesystem::path spec = target.at("spec").get<std::string>();
        set.target_spec = (spec.is_absolute() ? spec : std::filesystem::path(path).parent_path() / spec).lexically_normal().string();
        ImageDetections image;
        image.image = (std::filesystem::path(path).parent_path() / json.at("image").get<std::string>()).string();
        for (const nlohmann::json& corner : target.at("corners"))
          if (corner.at("visible").get<bool>())
            image.corners.push_back({corner.at("id").get<int>(),
                                     Eigen::Vector2d(corner.at("pixel").at(0).get<double>(), corner.at("pixel").at(1).get<double>())});
        set.images.push_back(std::move(image));
      }
    } catch (const nlohmann::json::exception& error) {
      throw InputError(InputMessage(path, "", std::string("not a ground-truth file: ") + error.what()));
    }
  }
  return set;
}

}  // namespace omnical

#include "calib/detections.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>

#include "model/io/atomic_write.h"
#include "model/input_error.h"
#include "model/io/json_file.h"

namespace omnical {

DetectionSet ReadDetections(const std::string& path) {
  const nlohmann::json json = ReadJsonFile(path);
  DetectionSet set;
  try {
    set.target_spec = json.at("target").get<std::string>();
    set.image_width_px = json.at("image_size").at(0).get<int>();
    set.image_height_px = json.at("image_size").at(1).get<int>();
    if (set.image_width_px < 1 || set.image_height_px < 1) throw InputError(InputMessage(path, "image_size", "must be positive"));
    const nlohmann::json& images = json.at("images");
    for (size_t i = 0; i < images.size(); ++i) {
      ImageDetections image;
      image.image = images[i].at("image").get<std::string>();
      std::set<int> seen;
      for (const nlohmann::json& corner : images[i].at("corners")) {
        CornerObservation c;
        c.id = corner.at("id").get<int>();
        c.pixel = Eigen::Vector2d(corner.at("pixel").at(0).get<double>(), corner.at("pixel").at(1).get<double>());
        c.unrefined = corner.contains("refined") && !corner.at("refined").get<bool>();
        const std::string where = "images[" + std::to_string(i) + "] (" + image.image + ")";
        if (!std::isfinite(c.pixel.x()) || !std::isfinite(c.pixel.y()))
          throw InputError(InputMessage(path, where, "corner " + std::to_string(c.id) + " has a non-finite pixel"));
        if (!seen.insert(c.id).second)
          throw InputError(InputMessage(path, where, "corner id " + std::to_string(c.id) + " appears twice"));
        image.corners.push_back(c);
      }
      set.images.push_back(std::move(image));
    }
  } catch (const nlohmann::json::exception& error) {
    throw InputError(InputMessage(path, "", std::string("unexpected structure: ") + error.what()));
  }
  return set;
}

void WriteDetections(const DetectionSet& detections, const std::string& path) {
  nlohmann::json json;
  json["target"] = detections.target_spec;
  json["image_size"] = {detections.image_width_px, detections.image_height_px};
  json["images"] = nlohmann::json::array();
  for (const ImageDetections& image : detections.images) {
    nlohmann::json entry;
    entry["image"] = image.image;
    entry["corners"] = nlohmann::json::array();
    for (const CornerObservation& c : image.corners) {
      nlohmann::json corner = {{"id", c.id}, {"pixel", {c.pixel.x(), c.pixel.y()}}};
      if (c.unrefined) corner["refined"] = false;
      entry["corners"].push_back(corner);
    }
    json["images"].push_back(entry);
  }
  WriteFileAtomically(path, [&](std::ostream& out) { out << json.dump(1) << '\n'; });
}


}  // namespace omnical

#include "calib/detections.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>

#include "model/io/atomic_write.h"
#include "model/input_error.h"
#include "model/io/json_file.h"

namespace omnical {

namespace {

// A whole number in int's range (3.0 too: numpy's tolist() writes floats), or InputError
// naming `field` (nlohmann's get<int> truncated 2.5, wrapped 2^40 and 2^64 - 1, and took
// true for 1).
int IntegerField(const nlohmann::json& value, const std::string& path, const std::string& field) {
  const double as_double = value.is_number() ? value.get<double>() : NAN;  // bool is not a number here
  if (!(std::isfinite(as_double) && as_double == std::floor(as_double) && as_double >= std::numeric_limits<int>::min() &&
        as_double <= std::numeric_limits<int>::max()))
    throw InputError(InputMessage(path, field, "must be a whole number of at most 10 digits (got " + value.dump() + ")"));
  return static_cast<int>(as_double);
}

std::string Number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", value);
  return text;
}

}  // namespace

DetectionSet ReadDetections(const std::string& path) {
  const nlohmann::json json = ReadJsonFile(path);
  DetectionSet set;
  try {
    set.target_spec = json.at("target").get<std::string>();
    if (json.contains("target_description")) set.target_description = json.at("target_description").get<std::string>();
    const nlohmann::json& size = json.at("image_size");
    if (!size.is_array() || size.size() != 2) throw InputError(InputMessage(path, "image_size", "must be [width, height]"));
    set.image_width_px = IntegerField(size[0], path, "image_size");
    set.image_height_px = IntegerField(size[1], path, "image_size");
    if (set.image_width_px < 1 || set.image_height_px < 1) throw InputError(InputMessage(path, "image_size", "must be positive"));
    const double width_px = set.image_width_px, height_px = set.image_height_px;
    const nlohmann::json& images = json.at("images");
    for (size_t i = 0; i < images.size(); ++i) {
      ImageDetections image;
      image.image = images[i].at("image").get<std::string>();
      const std::string where = "images[" + std::to_string(i) + "] (" + image.image + ")";
      std::set<int> seen;
      for (const nlohmann::json& corner : images[i].at("corners")) {
        CornerObservation c;
        c.id = IntegerField(corner.at("id"), path, where + ".id");
        const nlohmann::json& pixel = corner.at("pixel");
        if (!pixel.is_array() || pixel.size() != 2 || !pixel[0].is_number() || !pixel[1].is_number())
          throw InputError(InputMessage(path, where, "corner " + std::to_string(c.id) + "'s pixel must be [u, v]"));
        c.pixel = Eigen::Vector2d(pixel[0].get<double>(), pixel[1].get<double>());
        c.unrefined = corner.contains("refined") && !corner.at("refined").get<bool>();
        c.predicted = corner.contains("predicted") && corner.at("predicted").get<bool>();
        if (!std::isfinite(c.pixel.x()) || !std::isfinite(c.pixel.y()))
          throw InputError(InputMessage(path, where, "corner " + std::to_string(c.id) + " has a non-finite pixel"));
        // A detector's corner lies in its image; one an image size beyond it is corrupt (and
        // squared residuals of ~1e154 px overflow).
        if (c.pixel.x() < -width_px || c.pixel.x() > 2.0 * width_px || c.pixel.y() < -height_px || c.pixel.y() > 2.0 * height_px)
          throw InputError(InputMessage(path, where,
                                        "corner " + std::to_string(c.id) + "'s pixel (" + Number(c.pixel.x()) + ", " +
                                            Number(c.pixel.y()) + ") lies far outside the " +
                                            std::to_string(set.image_width_px) + " x " +
                                            std::to_string(set.image_height_px) + " image"));
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
  if (!detections.target_description.empty()) json["target_description"] = detections.target_description;
  json["image_size"] = {detections.image_width_px, detections.image_height_px};
  json["images"] = nlohmann::json::array();
  for (const ImageDetections& image : detections.images) {
    nlohmann::json entry;
    entry["image"] = image.image;
    entry["corners"] = nlohmann::json::array();
    for (const CornerObservation& c : image.corners) {
      nlohmann::json corner = {{"id", c.id}, {"pixel", {c.pixel.x(), c.pixel.y()}}};
      if (c.unrefined) corner["refined"] = false;
      if (c.predicted) corner["predicted"] = true;
      entry["corners"].push_back(corner);
    }
    json["images"].push_back(entry);
  }
  WriteFileAtomically(path, [&](std::ostream& out) { out << json.dump(1) << '\n'; });
}


}  // namespace omnical

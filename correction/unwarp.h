// Unwarping: omni images or video frames through a remap table to the virtual screen,
// through OpenCV's fixed-point maps for linear (RemapLinear: cv::remap's bytes, faster
// for 8-bit colour frames) and cubic (cv::remap), the float maps for nearest, which the
// fixed-point pair would round differently. The table comes from
// a directory written by `remap` or is made on the spot from a view request. Frames are
// read and written by the caller (video I/O stays at the front end); this file holds the
// checks, the frame loop and the image encoding.
#pragma once

#include <opencv2/core.hpp>

#include <functional>
#include <optional>
#include <string>

#include "correction/remap_table.h"
#include "correction/view_request.h"
#include "model/progress.h"

namespace omnical {

enum class Interpolation { kNearest, kLinear, kCubic };
// "nearest", "linear", "cubic".
std::optional<Interpolation> ParseInterpolation(const std::string& name);

class Unwarper {
 public:
  // `input_width_px` x `input_height_px`: the sensor's image, which every frame must match.
  Unwarper(RemapTable table, int input_width_px, int input_height_px, Interpolation interpolation);

  // From DIR (maps.json + maps.yml.gz). `sensor`, when given, must have the maps' image
  // size (InputError naming `sensor_name`, field image_size).
  static Unwarper FromMaps(const std::string& dir, Interpolation interpolation, const Sensor* sensor = nullptr,
                           const std::string& sensor_name = "");
  // A table made now (BuildRemapTable; progress stage "remap table").
  static Unwarper FromView(const Sensor& sensor, const ViewRequest& view, Interpolation interpolation,
                           const ProgressCallback& progress = nullptr);

  // The frame through the table; InputError naming `source` if its size is not the
  // sensor's image.
  cv::Mat Apply(const cv::Mat& frame, const std::string& source) const;

  int width_px() const { return map_x_.cols; }
  int height_px() const { return map_x_.rows; }

 private:
  int input_width_px_, input_height_px_;
  Interpolation interpolation_;
  cv::Mat map_x_, map_y_, map1_, map2_;  // float maps; their fixed-point pair
};

// Frames from `read` (false at the end) through the unwarper to `write`, reporting stage
// "unwarp" against `total_frames` (0: unknown); returns the number of frames. InputError
// naming `source` if it has none or a frame of the wrong size; Cancelled when the callback
// says stop. Decoding, remapping and encoding overlap: `read` is called on one thread and
// `write` on another (each always from the same one, in frame order), a few frames apart;
// `read` gets an empty Mat each time, and a frame's pixels must not change once it
// returns them (a reader refilling one buffer must copy). An exception
// from either reaches the caller, after the frames already unwarped are written.
long UnwarpFrames(const Unwarper& unwarper, const std::function<bool(cv::Mat*)>& read,
                  const std::function<void(const cv::Mat&)>& write, long total_frames, const std::string& source,
                  const ProgressCallback& progress = nullptr);

// True for the video extensions unwarp reads (.mp4, .avi, .mkv, .mov, .webm, .mpg, .mpeg, .m4v).
bool IsVideoPath(const std::string& path);
// The file's extension in lower case, with the dot ("" if none).
std::string LowerExtension(const std::string& path);

// Encodes by the path's extension (none: PNG) and writes atomically; InputError naming the
// path if the type cannot hold the image or the write fails.
void WriteImageFile(const std::string& path, const cv::Mat& image);

}  // namespace omnical

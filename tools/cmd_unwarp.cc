// omnical unwarp: an omni image or video through a remap table (from `remap --out DIR`, or
// made on the fly from view options) to the virtual screen.
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <optional>

#include "correction/map_export.h"
#include "model/atomic_write.h"
#include "model/input_error.h"
#include "tools/commands.h"
#include "calib/report/plot.h"
#include "tools/progress.h"
#include "tools/view_setup.h"

namespace omnical::cli {
namespace {

struct Options {
  std::string sensor_path, maps_dir, input, out, interpolation = "linear";
  ViewOptions view;
  bool view_given = false;
};

std::string LowerExtension(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(), [](unsigned char c) { return std::tolower(c); });
  return extension;
}

bool IsVideo(const std::string& path) {
  for (const char* extension : {".mp4", ".avi", ".mkv", ".mov", ".webm", ".mpg", ".mpeg", ".m4v"})
    if (LowerExtension(path) == extension) return true;
  return false;
}

void CheckFrameSize(const cv::Mat& frame, int width, int height, const std::string& input) {
  if (frame.cols != width || frame.rows != height)
    throw InputError(InputMessage(input, "", "is " + std::to_string(frame.cols) + " x " + std::to_string(frame.rows) +
                                                 " px but the sensor's image is " + std::to_string(width) + " x " +
                                                 std::to_string(height) + " px"));
}

void Run(const Options& options, const Context& context) {
  if (options.maps_dir.empty() == !options.view_given)
    throw InputError("unwarp: give either --maps DIR or view options (--view, --distance-mm | --n | --infinity, ...)");
  RemapTable table;
  int sensor_width = 0, sensor_height = 0;
  if (!options.maps_dir.empty()) {
    const MapsDescription maps = ReadMapsDescription(options.maps_dir, &table);
    try {
      sensor_width = maps.json.at("sensor").at("image_size_px").at(0).get<int>();
      sensor_height = maps.json.at("sensor").at("image_size_px").at(1).get<int>();
    } catch (const nlohmann::json::exception&) {
      throw InputError(InputMessage(options.maps_dir + "/maps.json", "sensor.image_size_px", "missing"));
    }
    if (!options.sensor_path.empty()) {
      const Sensor sensor = LoadSensorYaml(options.sensor_path);
      if (sensor.image_width_px() != sensor_width || sensor.image_height_px() != sensor_height)
        throw InputError(InputMessage(options.sensor_path, "image_size", "differs from the maps' sensor (" + options.maps_dir + "/maps.json)"));
    }
  } else {
    if (options.sensor_path.empty()) throw InputError("unwarp: --sensor is required with view options");
    const Sensor sensor = LoadSensorYaml(options.sensor_path);
    const ResolvedView resolved = ResolveView(sensor, options.view);
    Progress progress("remap table", resolved.settings.screen.height_px, context.quiet);
    table = BuildRemapTable(sensor, resolved.settings, [&](long rows) { progress.Advance(rows); });
    sensor_width = sensor.image_width_px(), sensor_height = sensor.image_height_px();
  }
  const cv::Mat map_x(table.height, table.width, CV_32F, table.map_x.data());
  const cv::Mat map_y(table.height, table.width, CV_32F, table.map_y.data());
  cv::Mat map1, map2;  // fixed point: cv::remap's fast path
  cv::convertMaps(map_x, map_y, map1, map2, CV_16SC2);
  const int interpolation = options.interpolation == "nearest" ? cv::INTER_NEAREST
                            : options.interpolation == "cubic" ? cv::INTER_CUBIC
                                                               : cv::INTER_LINEAR;
  auto unwarp = [&](const cv::Mat& frame) {
    cv::Mat out;
    if (interpolation == cv::INTER_NEAREST) cv::remap(frame, out, map_x, map_y, interpolation, cv::BORDER_CONSTANT);
    else cv::remap(frame, out, map1, map2, interpolation, cv::BORDER_CONSTANT);
    return out;
  };
  const std::filesystem::path out_dir = std::filesystem::path(options.out).parent_path();
  if (!out_dir.empty()) CreateOutputDirectory(out_dir);

  if (!IsVideo(options.input)) {
    const cv::Mat image = ReadImage(options.input, cv::IMREAD_UNCHANGED);
    if (image.empty()) throw InputError(InputMessage(options.input, "", "cannot be read as an image"));
    CheckFrameSize(image, sensor_width, sensor_height, options.input);
    if (IsVideo(options.out)) throw InputError(InputMessage(options.out, "", "an image input needs an image output"));
    std::vector<uchar> bytes;
    const std::string extension = LowerExtension(options.out);
    bool encoded = false;
    try {
      encoded = cv::imencode(extension.empty() ? ".png" : extension, unwarp(image), bytes);
    } catch (const cv::Exception&) {
    }
    if (!encoded) throw InputError(InputMessage(options.out, "", "cannot encode an image of this type (use .png, .jpg, .tif)"));
    WriteOutput(options.out, [&](std::ostream& out) { out.write(reinterpret_cast<const char*>(bytes.data()), bytes.size()); });
    if (!context.quiet) std::printf("%s -> %s (%dx%d)\n", options.input.c_str(), options.out.c_str(), table.width, table.height);
    return;
  }

  cv::VideoCapture capture(options.input);
  if (!capture.isOpened()) throw InputError(InputMessage(options.input, "", "cannot be opened as a video"));
  const std::string extension = LowerExtension(options.out);
  const int fourcc = extension == ".avi" ? cv::VideoWriter::fourcc('M', 'J', 'P', 'G')
                     : extension == ".mp4" || extension == ".m4v" || extension == ".mov"
                         ? cv::VideoWriter::fourcc('m', 'p', '4', 'v')
                         : 0;
  if (fourcc == 0) throw InputError(InputMessage(options.out, "", "video output must be .avi (MJPG) or .mp4 (mp4v)"));
  double fps = capture.get(cv::CAP_PROP_FPS);
  if (!(fps > 0.0 && fps < 1000.0)) fps = 25.0;
  const long frames = std::max(1L, static_cast<long>(capture.get(cv::CAP_PROP_FRAME_COUNT)));
  // The container is chosen by the file name, which the temporary file keeps.
  long written = 0;
  WriteFileAtomicallyByPath(options.out, [&](const std::string& temporary) {
    cv::VideoWriter writer;
    Progress progress("unwarp", frames, context.quiet);
    cv::Mat frame;
    while (capture.read(frame)) {
      if (written == 0) {
        CheckFrameSize(frame, sensor_width, sensor_height, options.input);
        if (!writer.open(temporary, fourcc, fps, cv::Size(table.width, table.height), frame.channels() == 3))
          throw InputError(InputMessage(options.out, "", "cannot be written as a video"));
      }
      writer.write(unwarp(frame));
      ++written;
      progress.Advance();
    }
    writer.release();
    if (written == 0) throw InputError(InputMessage(options.input, "", "has no readable frames"));
  });
  if (!context.quiet) std::printf("%s -> %s: %ld frames (%dx%d)\n", options.input.c_str(), options.out.c_str(), written, table.width, table.height);
}

}  // namespace

Command UnwarpCommand() {
  return {"unwarp", "Unwarp an omni image or video to a virtual screen (--maps DIR from `remap`, or view options)",
          [](CLI::App& sub, const Context& context) -> CommandAction {
            auto options = std::make_shared<Options>();
            sub.add_option("--sensor", options->sensor_path, "Sensor file (YAML); optional with --maps");
            sub.add_option("--maps", options->maps_dir, "Directory written by `omnical remap` (maps.json + maps.yml.gz)");
            sub.add_option("--input", options->input, "Omni image or video (.mp4, .avi, .mkv, .mov, ...)")->required();
            sub.add_option("--out", options->out, "Output image (.png, .jpg, ...) or video (.avi, .mp4)")->required();
            sub.add_option("--interpolation", options->interpolation, "nearest, linear or cubic")
                ->check(CLI::IsMember({"nearest", "linear", "cubic"}))
                ->capture_default_str();
            AddViewOptions(sub, &options->view, false);
            return [options, &context, &sub]() {
              options->view_given = AnyViewOptionGiven(sub);
              Run(*options, context);
            };
          }};
}

}  // namespace omnical::cli

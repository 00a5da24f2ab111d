// omnical unwarp: an omni image or video through a remap table (from `remap --out DIR`, or
// made on the fly from view options) to the virtual screen (correction/unwarp.h). Video
// files are opened here (model/io/codecs: OpenCV's videoio); the library holds the frame loop.
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>

#include "correction/unwarp.h"
#include "model/io/atomic_write.h"
#include "model/io/codecs/image_codecs.h"
#include "model/input_error.h"
#include "tools/commands.h"
#include "tools/progress.h"
#include "tools/view_options.h"
#include "model/io/sensor_yaml.h"

namespace omnical::cli {
namespace {

struct UnwarpFlags {
  std::string sensor_path, maps_dir, input, out, interpolation = "linear";
  ViewRequest view;
  bool view_given = false;
};

Unwarper MakeUnwarper(const UnwarpFlags& options, const ProgressCallback& progress) {
  if (options.maps_dir.empty() == !options.view_given)
    throw InputError("unwarp: give either --maps DIR or view options (--view, --distance-mm | --n | --infinity, ...)");
  const Interpolation interpolation = *ParseInterpolation(options.interpolation);
  if (!options.maps_dir.empty()) {
    if (options.sensor_path.empty()) return Unwarper::FromMaps(options.maps_dir, interpolation);
    const Sensor sensor = LoadSensorYaml(options.sensor_path);
    return Unwarper::FromMaps(options.maps_dir, interpolation, &sensor, options.sensor_path);
  }
  if (options.sensor_path.empty()) throw InputError("unwarp: --sensor is required with view options");
  const Sensor sensor = LoadSensorYaml(options.sensor_path);
  return NamingFlags(ViewFlags(), [&] { return Unwarper::FromView(sensor, options.view, interpolation, progress); });
}

// The video through the unwarper into options.out (MJPG .avi or mp4v .mp4), atomically.
long UnwarpVideo(const Unwarper& unwarper, const UnwarpFlags& options, const ProgressCallback& progress) {
  // Checked here, and read through FFmpeg alone (OpenVideoFile): OpenCV otherwise tries
  // GStreamer and an image-sequence reader first, and each failure printed several lines
  // before our one.
  std::error_code error;
  if (!std::filesystem::exists(options.input, error)) throw InputError(InputMessage(options.input, "", "file not found"));
  if (!std::filesystem::is_regular_file(options.input, error))
    throw InputError(InputMessage(options.input, "",
                                  std::filesystem::is_directory(options.input, error) ? "is a directory, not a file"
                                                                                       : "is not a regular file"));
  if (std::filesystem::file_size(options.input, error) == 0) throw InputError(InputMessage(options.input, "", "is empty"));
  // FFmpeg's own messages on a corrupt file ("[png @ 0x...] chunk too big") too, unless
  // the user asked for them: OpenCV reads this when it first starts FFmpeg.
  ::setenv("OPENCV_FFMPEG_LOGLEVEL", "-8", 0);  // AV_LOG_QUIET
  const std::unique_ptr<VideoFrameReader> capture = OpenVideoFile(options.input);
  if (!capture) throw InputError(InputMessage(options.input, "", "cannot be opened as a video"));
  const std::string extension = LowerExtension(options.out);
  const int fourcc = extension == ".avi"                                              ? VideoFourcc('M', 'J', 'P', 'G')
                     : extension == ".mp4" || extension == ".m4v" || extension == ".mov" ? VideoFourcc('m', 'p', '4', 'v')
                                                                                         : 0;
  if (fourcc == 0) throw InputError(InputMessage(options.out, "", "video output must be .avi (MJPG) or .mp4 (mp4v)"));
  double fps = capture->FramesPerSecond();
  if (!(fps > 0.0 && fps < 1000.0)) fps = 25.0;
  const long total = std::max(1L, capture->FrameCount());
  long frames = 0;
  // The container is chosen by the file name, which the temporary file keeps.
  WriteFileAtomicallyByPath(options.out, [&](const std::string& temporary) {
    std::unique_ptr<VideoFrameWriter> writer;
    auto write = [&](const cv::Mat& frame) {
      if (!writer &&
          !(writer = CreateVideoFile(temporary, fourcc, fps, cv::Size(unwarper.width_px(), unwarper.height_px()),
                                     frame.channels() == 3)))
        throw InputError(InputMessage(options.out, "", "cannot be written as a video"));
      writer->Write(frame);
    };
    frames = UnwarpFrames(unwarper, [&](cv::Mat* frame) { return capture->Read(frame); }, write, total, options.input, progress);
    if (writer) writer->Close();
  });
  return frames;
}

void RunUnwarp(const UnwarpFlags& options, const Context& context) {
  const ProgressCallback progress = TerminalProgress(context);
  const Unwarper unwarper = MakeUnwarper(options, progress);
  const std::filesystem::path out_dir = std::filesystem::path(options.out).parent_path();
  if (!out_dir.empty()) CreateOutputDirectory(out_dir);
  if (IsVideoPath(options.input)) {
    const long frames = UnwarpVideo(unwarper, options, progress);
    if (!context.quiet)
      std::printf("%s -> %s: %ld frames (%dx%d)\n", options.input.c_str(), options.out.c_str(), frames, unwarper.width_px(),
                  unwarper.height_px());
    return;
  }
  const cv::Mat image = ReadImage(options.input, cv::IMREAD_UNCHANGED);
  if (image.empty()) throw InputError(InputMessage(options.input, "", "cannot be read as an image"));
  const cv::Mat unwarped = unwarper.Apply(image, options.input);
  if (IsVideoPath(options.out)) throw InputError(InputMessage(options.out, "", "an image input needs an image output"));
  WriteImageFile(options.out, unwarped);
  if (!context.quiet)
    std::printf("%s -> %s (%dx%d)\n", options.input.c_str(), options.out.c_str(), unwarper.width_px(), unwarper.height_px());
}

}  // namespace

Command UnwarpCommand() {
  return {"unwarp", "Unwarp an omni image or video to a virtual screen (--maps DIR from `remap`, or view options)",
          [](CLI::App& sub, const Context& context) -> CommandAction {
            auto options = std::make_shared<UnwarpFlags>();
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
              RunUnwarp(*options, context);
            };
          }};
}

}  // namespace omnical::cli

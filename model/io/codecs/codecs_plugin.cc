// libomnical_codecs_plugin.so: the only code of omnical that links OpenCV's imgcodecs and
// videoio (image_codecs.h says why they are loaded apart).
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <opencv2/videoio/registry.hpp>

#include <cmath>

#include "model/io/codecs/codecs_plugin_table.h"

namespace omnical {
namespace {

// A container's property as the reader promises it: 0 when unknown (NaN, infinite, negative).
double KnownOrZero(double value) { return std::isfinite(value) && value > 0 ? value : 0.0; }

class CaptureReader : public VideoFrameReader {
 public:
  explicit CaptureReader(const std::string& path)
      // Through FFmpeg alone where OpenCV has it: otherwise OpenCV tries GStreamer and an
      // image-sequence reader first, and each failure prints lines of its own.
      : capture_(path, cv::videoio_registry::hasBackend(cv::CAP_FFMPEG) ? cv::CAP_FFMPEG : cv::CAP_ANY) {}
  bool IsOpened() const { return capture_.isOpened(); }
  bool Read(cv::Mat* frame) override { return capture_.read(*frame); }
  double FramesPerSecond() const override { return KnownOrZero(capture_.get(cv::CAP_PROP_FPS)); }
  long FrameCount() const override {
    // A broken container can report NaN or a huge count, whose cast to long is undefined.
    const double count = KnownOrZero(capture_.get(cv::CAP_PROP_FRAME_COUNT));
    return count < 1e15 ? static_cast<long>(count) : 0;
  }

 private:
  cv::VideoCapture capture_;
};

class WriterSink : public VideoFrameWriter {
 public:
  bool Open(const std::string& path, int fourcc, double fps, cv::Size size, bool colour) {
    return writer_.open(path, fourcc, fps, size, colour);
  }
  void Write(const cv::Mat& frame) override { writer_.write(frame); }
  void Close() override { writer_.release(); }

 private:
  cv::VideoWriter writer_;
};

cv::Mat LoadImage(const std::string& path, int flags) { return cv::imread(path, flags); }

bool Encode(const std::string& extension, const cv::Mat& image, std::vector<unsigned char>* bytes,
            const std::vector<int>& params) {
  return cv::imencode(extension, image, *bytes, params);
}

std::unique_ptr<VideoFrameReader> OpenVideo(const std::string& path) {
  auto reader = std::make_unique<CaptureReader>(path);
  if (!reader->IsOpened()) return nullptr;
  return reader;
}

std::unique_ptr<VideoFrameWriter> CreateVideo(const std::string& path, int fourcc, double fps, cv::Size size,
                                              bool colour) {
  auto writer = std::make_unique<WriterSink>();
  if (!writer->Open(path, fourcc, fps, size, colour)) return nullptr;
  return writer;
}

const CodecsPluginTable kTable = {kCodecsPluginTableVersion, kCodecsPluginBuild, LoadImage, Encode, OpenVideo, CreateVideo};

}  // namespace
}  // namespace omnical

extern "C" __attribute__((visibility("default"))) const omnical::CodecsPluginTable* omnical_codecs_plugin_table() {
  return &omnical::kTable;
}

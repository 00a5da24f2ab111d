// Image and video files through OpenCV's codecs (imgcodecs, videoio), loaded the first time
// a file is read or written. Linked, those two libraries bring ~240 more shared libraries
// (GDAL, DICOM, FFmpeg, GStreamer...) into every process that links omnical, and loading
// them was most of each process's start (~0.25 s of an `omnical` call, ~0.17 s of a test
// program's), where projecting points or fitting detections never touches a file of
// pixels (tests/bench/startup_cost.py). They live in a plugin, libomnical_codecs_plugin.so,
// in <libdir>/omnical of the build tree or the install prefix, and are found as
// docs/library-api.md says (from the build tree for programs in it, beside an installed
// program or Python package, through the RUNPATH omnical's CMake package gives programs built against it, or
// in the configured install directory); the environment variable OMNICAL_CODECS_PLUGIN,
// when set, names the one file to load. The first call of any function below loads it, and
// throws InputError (naming OMNICAL_CODECS_PLUGIN and each path tried) when no plugin of
// this build can be loaded; after that they fail only as their OpenCV counterparts do.
#pragma once

#include <opencv2/core.hpp>

#include <memory>
#include <string>
#include <vector>

namespace omnical {

// cv::imread: the image, or an empty Mat when the file cannot be read as one.
cv::Mat LoadImageFile(const std::string& path, int imread_flags);

// cv::imencode: the image in the format of `extension` (".png", ".jpg"...) with OpenCV's
// IMWRITE_* parameters. False when the codec refused it; throws cv::Exception as
// cv::imencode does (an extension no codec writes).
bool EncodeImage(const std::string& extension, const cv::Mat& image, std::vector<unsigned char>* bytes,
                 const std::vector<int>& imwrite_params = {});

// A video file's frames in order (cv::VideoCapture through FFmpeg where OpenCV has it).
class VideoFrameReader {
 public:
  virtual ~VideoFrameReader() = default;
  virtual bool Read(cv::Mat* frame) = 0;  // false at the end
  virtual double FramesPerSecond() const = 0;  // as the container says; 0 when unknown
  virtual long FrameCount() const = 0;         // as the container says; 0 when unknown
};

// A video file being written (cv::VideoWriter).
class VideoFrameWriter {
 public:
  virtual ~VideoFrameWriter() = default;
  virtual void Write(const cv::Mat& frame) = 0;
  virtual void Close() = 0;  // finishes the file
};

// nullptr when `path` cannot be opened as a video.
std::unique_ptr<VideoFrameReader> OpenVideoFile(const std::string& path);
// nullptr when no codec writes `fourcc` to `path` (its extension picks the container).
std::unique_ptr<VideoFrameWriter> CreateVideoFile(const std::string& path, int fourcc, double frames_per_second,
                                                  cv::Size frame_size_px, bool colour);

// cv::VideoWriter::fourcc: four characters as OpenCV's codec code.
constexpr int VideoFourcc(char c1, char c2, char c3, char c4) {
  return (c1 & 255) + ((c2 & 255) << 8) + ((c3 & 255) << 16) + ((c4 & 255) << 24);
}

}  // namespace omnical

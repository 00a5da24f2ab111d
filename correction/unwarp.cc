#include "correction/unwarp.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cctype>
#include <condition_variable>
#include <deque>
#include <exception>
#include <filesystem>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include "correction/bilinear_remap.h"
#include "correction/maps_json.h"
#include "model/io/atomic_write.h"
#include "model/io/codecs/image_codecs.h"
#include "model/first_error.h"
#include "model/forced_unwind.h"
#include "model/input_error.h"

namespace omnical {

std::optional<Interpolation> ParseInterpolation(const std::string& name) {
  if (name == "nearest") return Interpolation::kNearest;
  if (name == "linear") return Interpolation::kLinear;
  if (name == "cubic") return Interpolation::kCubic;
  return std::nullopt;
}

Unwarper::Unwarper(RemapTable table, int input_width_px, int input_height_px, Interpolation interpolation)
    : input_width_px_(input_width_px), input_height_px_(input_height_px), interpolation_(interpolation) {
  map_x_ = cv::Mat(table.height, table.width, CV_32F, table.map_x.data()).clone();
  map_y_ = cv::Mat(table.height, table.width, CV_32F, table.map_y.data()).clone();
  cv::convertMaps(map_x_, map_y_, map1_, map2_, CV_16SC2);
}

Unwarper Unwarper::FromMaps(const std::string& dir, Interpolation interpolation, const Sensor* sensor,
                            const std::string& sensor_name) {
  RemapTable table;
  const MapsDescription maps = ReadMapsDescription(dir, &table);
  if (maps.sensor_width_px <= 0 || maps.sensor_height_px <= 0)
    throw InputError(InputMessage(maps.path, "sensor.image_size_px", "missing"));
  if (sensor != nullptr && (sensor->image_width_px() != maps.sensor_width_px || sensor->image_height_px() != maps.sensor_height_px))
    throw InputError(InputMessage(sensor_name, "image_size", "differs from the maps' sensor (" + maps.path + ")"));
  return Unwarper(std::move(table), maps.sensor_width_px, maps.sensor_height_px, interpolation);
}

Unwarper Unwarper::FromView(const Sensor& sensor, const ViewRequest& view, Interpolation interpolation,
                            const ProgressCallback& progress) {
  return Unwarper(BuildRemapTable(sensor, ResolveView(sensor, view).settings, progress), sensor.image_width_px(),
                  sensor.image_height_px(), interpolation);
}

cv::Mat Unwarper::Apply(const cv::Mat& frame, const std::string& source) const {
  if (frame.cols != input_width_px_ || frame.rows != input_height_px_)
    throw InputError(InputMessage(source, "", "is " + std::to_string(frame.cols) + " x " + std::to_string(frame.rows) +
                                                  " px but the sensor's image is " + std::to_string(input_width_px_) + " x " +
                                                  std::to_string(input_height_px_) + " px"));
  cv::Mat out;
  if (interpolation_ == Interpolation::kNearest)
    cv::remap(frame, out, map_x_, map_y_, cv::INTER_NEAREST, cv::BORDER_CONSTANT);
  else if (interpolation_ == Interpolation::kLinear)
    RemapLinear(frame, map1_, map2_, &out);
  else
    cv::remap(frame, out, map1_, map2_, cv::INTER_CUBIC, cv::BORDER_CONSTANT);
  return out;
}

namespace {

// A bounded hand-over between two pipeline stages. Close() ends it: Pop then drains what is
// left and returns false; Push returns false (the consumer has gone).
class FrameQueue {
 public:
  explicit FrameQueue(size_t capacity) : capacity_(capacity) {}
  bool Push(cv::Mat frame) {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [&] { return closed_ || frames_.size() < capacity_; });
    if (closed_) return false;
    frames_.push_back(std::move(frame));
    changed_.notify_all();
    return true;
  }
  bool Pop(cv::Mat* frame) {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [&] { return closed_ || !frames_.empty(); });
    if (frames_.empty()) return false;
    *frame = std::move(frames_.front());
    frames_.pop_front();
    changed_.notify_all();
    return true;
  }
  void Close() {
    std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
    changed_.notify_all();
  }

 private:
  const size_t capacity_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<cv::Mat> frames_;
  bool closed_ = false;
};

}  // namespace

long UnwarpFrames(const Unwarper& unwarper, const std::function<bool(cv::Mat*)>& read,
                  const std::function<void(const cv::Mat&)>& write, long total_frames, const std::string& source,
                  const ProgressCallback& progress) {
  ProgressReporter reporter(progress, "unwarp", total_frames);
  // Three stages overlap: decoding on one thread, the remap here, encoding on another, a
  // couple of frames queued between them (video decode and encode are mostly one-threaded;
  // the remap is a few ms). Each frame is read into a fresh Mat: a queued frame must not
  // share its buffer with the next read. Frames are written in order; when a stage fails
  // or the callback says stop, the frames already unwarped are still written, the other
  // stages end, and the first error is rethrown here.
  constexpr size_t kQueuedFrames = 3;
  FrameQueue decoded(kQueuedFrames), unwarped(kQueuedFrames);
  FirstError error;
  std::thread reader([&] {
    try {
      for (;;) {
        cv::Mat frame;
        if (!read(&frame) || !decoded.Push(std::move(frame))) break;
      }
    } OMNICAL_RETHROW_FORCED_UNWIND catch (...) {
      error.Keep(std::current_exception());
    }
    decoded.Close();
  });
  std::thread writer;
  try {
    writer = std::thread([&] {
      try {
        for (cv::Mat frame; unwarped.Pop(&frame);) write(frame);
      } OMNICAL_RETHROW_FORCED_UNWIND catch (...) {
        error.Keep(std::current_exception());
        decoded.Close();  // stops the reader; the remap loop then ends
      }
      unwarped.Close();
    });
  } catch (...) {  // no thread to write on (std::system_error): a joinable reader must not be destroyed
    decoded.Close();
    reader.join();
    throw;
  }
  long frames = 0;
  try {
    for (cv::Mat frame; decoded.Pop(&frame);) {
      if (!unwarped.Push(unwarper.Apply(frame, source))) break;  // the writer failed
      ++frames;
      reporter.Step();
    }
  } OMNICAL_RETHROW_FORCED_UNWIND catch (...) {
    error.Keep(std::current_exception());
  }
  decoded.Close();
  unwarped.Close();
  reader.join();
  writer.join();
  error.RethrowIfAny();
  if (frames == 0) throw InputError(InputMessage(source, "", "has no readable frames"));
  return frames;
}

std::string LowerExtension(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(), [](unsigned char c) { return std::tolower(c); });
  return extension;
}

bool IsVideoPath(const std::string& path) {
  const std::string extension = LowerExtension(path);
  for (const char* video : {".mp4", ".avi", ".mkv", ".mov", ".webm", ".mpg", ".mpeg", ".m4v"})
    if (extension == video) return true;
  return false;
}

void WriteImageFile(const std::string& path, const cv::Mat& image) {
  std::vector<uchar> bytes;
  const std::string extension = LowerExtension(path);
  bool encoded = false;
  try {
    encoded = EncodeImage(extension.empty() ? ".png" : extension, image, &bytes);
  } catch (const cv::Exception&) {
  }
  if (!encoded) throw InputError(InputMessage(path, "", "cannot encode an image of this type (use .png, .jpg, .tif)"));
  WriteFileAtomically(path, [&](std::ostream& out) { out.write(reinterpret_cast<const char*>(bytes.data()), bytes.size()); });
}

}  // namespace omnical

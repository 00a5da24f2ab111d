// Helper of tests/cli/remap_test.sh, with OpenCV on the test side of the comparison:
//   mapcheck ffmpeg OMNI.png MAPS.yml.gz FFMPEG.png   ffmpeg's output == cv::remap INTER_NEAREST
//                                                      on the rounded float maps, pixel for pixel
//   mapcheck dump MAPS.yml.gz X.f32 Y.f32             the float maps as raw little-endian float32
//   mapcheck same-size IMAGE W H                      the image is W x H
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

namespace {

bool ReadMaps(const std::string& path, cv::Mat* x, cv::Mat* y) {
  cv::FileStorage fs(path, cv::FileStorage::READ);
  if (!fs.isOpened()) return false;
  fs["map_x"] >> *x;
  fs["map_y"] >> *y;
  return !x->empty() && x->size() == y->size();
}

}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "";
  if (mode == "ffmpeg" && argc == 5) {
    const cv::Mat omni = cv::imread(argv[2], cv::IMREAD_GRAYSCALE), from_ffmpeg = cv::imread(argv[4], cv::IMREAD_GRAYSCALE);
    cv::Mat x, y;
    if (omni.empty() || from_ffmpeg.empty() || !ReadMaps(argv[3], &x, &y)) return std::fprintf(stderr, "unreadable input\n"), 1;
    for (auto* map : {&x, &y})
      for (float& v : cv::Mat_<float>(*map)) v = v < -0.5f ? -1.0f : std::round(v);
    cv::Mat expected;
    cv::remap(omni, expected, x, y, cv::INTER_NEAREST, cv::BORDER_CONSTANT, 0);
    if (expected.size() != from_ffmpeg.size()) return std::fprintf(stderr, "sizes differ\n"), 1;
    const int differing = cv::countNonZero(expected != from_ffmpeg);
    std::printf("ffmpeg vs cv::remap: %d of %d pixels differ\n", differing, static_cast<int>(expected.total()));
    return differing == 0 ? 0 : 1;
  }
  if (mode == "dump" && argc == 5) {
    cv::Mat x, y;
    if (!ReadMaps(argv[2], &x, &y)) return std::fprintf(stderr, "unreadable maps\n"), 1;
    for (const auto& [map, path] : {std::pair{x, argv[3]}, std::pair{y, argv[4]}}) {
      std::ofstream out(path, std::ios::binary);
      const cv::Mat continuous = map.clone();
      out.write(reinterpret_cast<const char*>(continuous.data), continuous.total() * sizeof(float));  // x86: little-endian
    }
    return 0;
  }
  if (mode == "same-size" && argc == 5) {
    const cv::Mat image = cv::imread(argv[2], cv::IMREAD_UNCHANGED);
    return !image.empty() && image.cols == std::atoi(argv[3]) && image.rows == std::atoi(argv[4]) ? 0 : 1;
  }
  std::fprintf(stderr, "usage: mapcheck ffmpeg|dump|same-size ...\n");
  return 2;
}

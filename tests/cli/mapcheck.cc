// Helper of tests/cli/remap_test.sh, with OpenCV on the test side of the comparison:
//   mapcheck ffmpeg OMNI.png MAPS.yml.gz FFMPEG.png   ffmpeg's output == cv::remap INTER_NEAREST
//                                                      on the rounded float maps, pixel for pixel
//   mapcheck dump MAPS.yml.gz X.f32 Y.f32             the float maps as raw little-endian float32
//   mapcheck same-size IMAGE W H                      the image is W x H
//   mapcheck compare MAPS_A.yml.gz MAPS_B.yml.gz      prints "max_px rms_px common flipped": the
//                                                      distance between the two tables' omni
//                                                      pixels where both are valid, their
//                                                      count, and how many are valid in one only
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
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
  if (mode == "compare" && argc == 4) {
    cv::Mat ax, ay, bx, by;
    if (!ReadMaps(argv[2], &ax, &ay) || !ReadMaps(argv[3], &bx, &by) || ax.size() != bx.size())
      return std::fprintf(stderr, "unreadable or differently sized maps\n"), 1;
    double worst = 0.0, squares = 0.0;
    long common = 0, flipped = 0;
    for (int r = 0; r < ax.rows; ++r) {
      for (int c = 0; c < ax.cols; ++c) {
        const bool a_valid = ax.at<float>(r, c) >= 0.0f, b_valid = bx.at<float>(r, c) >= 0.0f;
        if (a_valid != b_valid) ++flipped;
        if (!a_valid || !b_valid) continue;
        const double d = std::hypot(ax.at<float>(r, c) - bx.at<float>(r, c), ay.at<float>(r, c) - by.at<float>(r, c));
        worst = std::max(worst, d);
        squares += d * d;
        ++common;
      }
    }
    std::printf("%.6f %.6f %ld %ld\n", worst, common > 0 ? std::sqrt(squares / common) : 0.0, common, flipped);
    return common > 0 ? 0 : 1;
  }
  std::fprintf(stderr, "usage: mapcheck ffmpeg|dump|same-size|compare ...\n");
  return 2;
}

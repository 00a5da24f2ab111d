// RemapLinear against cv::remap, byte for byte: the unwarp's promise is OpenCV's result
// for the same fixed-point maps, only faster. Exact equality is the tolerance because both
// are integer arithmetic on the same 1/32 px fractions.
#include "correction/bilinear_remap.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <cstdint>
#include <vector>

namespace omnical {
namespace {

// Fixed-point maps whose first rows put every one of the 1024 fractions at taps inside the
// frame, and whose other rows scatter taps over and past its border (up to 3 px out), so
// that most groups of eight mix inside and border pixels. The width is not a multiple of 8.
void MakeMaps(cv::Size frame, cv::Mat* map1, cv::Mat* map2) {
  const int width = 1029, inside_rows = 6, border_rows = 10;
  map1->create(inside_rows + border_rows, width, CV_16SC2);
  map2->create(map1->size(), CV_16UC1);
  cv::RNG rng(7);
  for (int v = 0; v < map1->rows; ++v) {
    for (int u = 0; u < width; ++u) {
      cv::Vec2s& xy = map1->at<cv::Vec2s>(v, u);
      if (v < inside_rows) {
        xy[0] = static_cast<short>(rng.uniform(0, std::max(frame.width - 1, 1)));
        xy[1] = static_cast<short>(rng.uniform(0, std::max(frame.height - 1, 1)));
        map2->at<uint16_t>(v, u) = static_cast<uint16_t>((v * width + u) % 1024);
      } else {
        xy[0] = static_cast<short>(rng.uniform(-3, frame.width + 3));
        xy[1] = static_cast<short>(rng.uniform(-3, frame.height + 3));
        map2->at<uint16_t>(v, u) = static_cast<uint16_t>(rng.uniform(0, 1024));
      }
    }
  }
}

cv::Mat Frame(cv::Size size, int seed) {
  cv::Mat frame(size, CV_8UC3);
  cv::RNG rng(seed);
  rng.fill(frame, cv::RNG::UNIFORM, 0, 256);
  // The extremes, where rounding and saturation would show.
  for (int y = 0; y < size.height; y += 2) frame.row(y).colRange(0, size.width / 2).setTo(cv::Scalar(255, 255, 255));
  for (int y = 1; y < size.height; y += 2) frame.row(y).colRange(size.width / 2, size.width).setTo(cv::Scalar(0, 255, 0));
  return frame;
}

int DifferingBytes(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != b.type()) return -1;
  return cv::countNonZero(cv::Mat(a != b).reshape(1));
}

cv::Mat OpenCvRemap(const cv::Mat& frame, const cv::Mat& map1, const cv::Mat& map2) {
  cv::Mat out;
  cv::remap(frame, out, map1, map2, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  return out;
}

bool CpuHasAvx2() { return __builtin_cpu_supports("avx2"); }

TEST(RemapLinear, EveryFractionAndEveryBorderCaseGivesCvRemapsBytes) {
  for (const cv::Size size : {cv::Size(29, 17), cv::Size(64, 3)}) {
    const cv::Mat frame = Frame(size, size.width);
    cv::Mat map1, map2, out;
    MakeMaps(size, &map1, &map2);
    EXPECT_EQ(RemapLinearHasFastPath(frame, map1, map2), CpuHasAvx2());
    RemapLinear(frame, map1, map2, &out);
    EXPECT_EQ(DifferingBytes(out, OpenCvRemap(frame, map1, map2)), 0) << size;
  }
}

TEST(RemapLinear, HighFractionBitsFarCoordinatesAndCutOutMapsAsCvRemap) {
  const cv::Mat frame = Frame({37, 13}, 17);
  // Maps cut from larger ones (rows not contiguous); fraction words over the whole 16-bit
  // range (OpenCV uses the low 10 bits); coordinates out to the int16 limits.
  cv::Mat larger1(40, 1100, CV_16SC2), larger2(40, 1100, CV_16UC1);
  cv::Mat map1 = larger1(cv::Rect(30, 5, 1029, 16)), map2 = larger2(cv::Rect(30, 5, 1029, 16));
  MakeMaps(frame.size(), &map1, &map2);
  ASSERT_FALSE(map1.isContinuous());
  cv::RNG rng(23);
  for (int v = 0; v < map1.rows; ++v) {
    for (int u = 0; u < map1.cols; ++u) {
      map2.at<uint16_t>(v, u) = static_cast<uint16_t>(map2.at<uint16_t>(v, u) + 1024 * rng.uniform(0, 64));
      if (v % 4 == 3 && u % 7 == 0) {
        cv::Vec2s& xy = map1.at<cv::Vec2s>(v, u);
        xy[u % 2] = static_cast<short>(u % 3 == 0 ? -32768 : 32767);
      }
    }
  }
  cv::Mat out;
  RemapLinear(frame, map1, map2, &out);
  EXPECT_EQ(DifferingBytes(out, OpenCvRemap(frame, map1, map2)), 0);
}

TEST(RemapLinear, ReadsNoByteBeyondAnExactlySizedFrame) {
  // The frame is the whole of its allocation, so under AddressSanitizer (the CI's second
  // pass) a read past its last byte stops the test. The taps sit at the last pixels the
  // eight-byte reads may start from (row 0), and just past them (rows 1-3), eight alike
  // in a row so that a looser bound would take them all at once.
  const cv::Size size(21, 6);
  std::vector<uint8_t> pixels(static_cast<size_t>(size.area()) * 3);
  const cv::Mat frame(size, CV_8UC3, pixels.data());
  Frame(size, 19).copyTo(frame);
  cv::Mat map1(4, 64, CV_16SC2), map2(4, 64, CV_16UC1, cv::Scalar(1023));
  for (int v = 0; v < map1.rows; ++v)
    for (int u = 0; u < map1.cols; ++u)
      map1.at<cv::Vec2s>(v, u) =
          cv::Vec2s(static_cast<short>(size.width - 3 + v % 3), static_cast<short>(size.height - 2 + v / 3));
  cv::Mat out;
  RemapLinear(frame, map1, map2, &out);
  EXPECT_EQ(DifferingBytes(out, OpenCvRemap(frame, map1, map2)), 0);
}

TEST(RemapLinear, AFrameCutFromALargerImageReadsNothingBeyondItsEdges) {
  // White all round: a tap read past the cut would show as a bright pixel.
  cv::Mat larger(30, 50, CV_8UC3, cv::Scalar(255, 255, 255));
  const cv::Rect cut(5, 4, 29, 17);
  Frame(cut.size(), 3).copyTo(larger(cut));
  const cv::Mat frame = larger(cut);
  ASSERT_FALSE(frame.isContinuous());
  cv::Mat map1, map2, out;
  MakeMaps(frame.size(), &map1, &map2);
  RemapLinear(frame, map1, map2, &out);
  EXPECT_EQ(DifferingBytes(out, OpenCvRemap(frame, map1, map2)), 0);
}

TEST(RemapLinear, FramesTooSmallForEightByteReadsStillMatch) {
  for (const cv::Size size : {cv::Size(1, 1), cv::Size(2, 1), cv::Size(1, 2), cv::Size(2, 2), cv::Size(3, 2)}) {
    const cv::Mat frame = Frame(size, 11);
    cv::Mat map1, map2, out;
    MakeMaps(size, &map1, &map2);
    RemapLinear(frame, map1, map2, &out);
    EXPECT_EQ(DifferingBytes(out, OpenCvRemap(frame, map1, map2)), 0) << size;
  }
}

TEST(RemapLinear, WritingOverItsOwnFrameGivesWhatACopyWouldHave) {
  cv::Mat frame = Frame({40, 20}, 5), map1, map2;
  MakeMaps(frame.size(), &map1, &map2);
  const cv::Mat expected = OpenCvRemap(frame.clone(), map1, map2);
  RemapLinear(frame, map1, map2, &frame);
  EXPECT_EQ(DifferingBytes(frame, expected), 0);
}

TEST(RemapLinear, OtherFrameTypesGoToCvRemap) {
  cv::Mat map1, map2;
  MakeMaps({29, 17}, &map1, &map2);
  for (const int type : {CV_8UC1, CV_8UC4, CV_16UC3, CV_32FC3}) {
    cv::Mat frame(17, 29, type), out;
    cv::randu(frame, 0, 200);
    EXPECT_FALSE(RemapLinearHasFastPath(frame, map1, map2)) << type;
    RemapLinear(frame, map1, map2, &out);
    EXPECT_EQ(DifferingBytes(out, OpenCvRemap(frame, map1, map2)), 0) << type;
  }
  // Not an image: a 3-D array of pixels.
  const int sizes[3] = {4, 17, 29};
  cv::Mat volume(3, sizes, CV_8UC3, cv::Scalar(100, 100, 100));
  EXPECT_FALSE(RemapLinearHasFastPath(volume, map1, map2));
  // Rows over 32767 bytes: the kernel's 16-bit offset arithmetic would overflow.
  const cv::Mat wide = Frame({11000, 3}, 13);
  cv::Mat out;
  EXPECT_FALSE(RemapLinearHasFastPath(wide, map1, map2));
  RemapLinear(wide, map1, map2, &out);
  EXPECT_EQ(DifferingBytes(out, OpenCvRemap(wide, map1, map2)), 0);
}

}  // namespace
}  // namespace omnical

// Bilinear remap of 8-bit 3-channel frames through OpenCV's fixed-point maps: the same
// bytes as cv::remap(frame, out, map1, map2, INTER_LINEAR, BORDER_CONSTANT, 0), 1.7x as
// fast on one thread (docs/remap-speed.md). cv::remap spends most of its time
// per pixel on table look-ups and narrow loads; this kernel takes eight pixels at a time
// with AVX2, where the CPU has it. Everything it does not handle goes to cv::remap.
#pragma once

#include <opencv2/core.hpp>

namespace omnical {

// `map1` CV_16SC2 (the top-left tap), `map2` CV_16UC1 (the 1/32 px fraction index), as
// cv::convertMaps(..., CV_16SC2) makes them. `out` gets map1's size and frame's type.
// Other frame types, other map types, a CPU without AVX2 or a row step over 32767 bytes:
// cv::remap itself. Rows spread over OpenCV's threads, as cv::remap's do.
void RemapLinear(const cv::Mat& frame, const cv::Mat& map1, const cv::Mat& map2, cv::Mat* out);

// True when RemapLinear takes its own kernel for this frame on this CPU.
bool RemapLinearHasFastPath(const cv::Mat& frame, const cv::Mat& map1, const cv::Mat& map2);

}  // namespace omnical

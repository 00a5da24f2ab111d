// Bilinear sample of a one-channel image at a sub-pixel position (pixel-centre
// coordinates: pixel (0, 0) has its centre at (0, 0)); NaN where a neighbour is outside.
#pragma once

#include <opencv2/core.hpp>

#include <cmath>

namespace omnical {

template <typename Pixel>
double Bilinear(const cv::Mat& image, double x, double y) {
  if (!std::isfinite(x) || !std::isfinite(y)) return NAN;
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= image.cols || y0 + 1 >= image.rows) return NAN;
  const double a = x - x0, b = y - y0;
  return (1 - a) * (1 - b) * image.at<Pixel>(y0, x0) + a * (1 - b) * image.at<Pixel>(y0, x0 + 1) +
         (1 - a) * b * image.at<Pixel>(y0 + 1, x0) + a * b * image.at<Pixel>(y0 + 1, x0 + 1);
}

}  // namespace omnical

// The figure helpers' colour lookup against OpenCV's own colour maps.
#include "calib/report/plot.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <cmath>

namespace omnical {
namespace {

cv::Scalar OpenCvColour(int colormap, int level) {
  cv::Mat one(1, 1, CV_8UC1, cv::Scalar(level)), colour;
  cv::applyColorMap(one, colour, colormap);
  const cv::Vec3b c = colour.at<cv::Vec3b>(0, 0);
  return cv::Scalar(c[0], c[1], c[2]);
}

// Exact: the lookup must give the colour cv::applyColorMap gives the same 8-bit level.
TEST(ColourMapColour, MatchesApplyColorMapAtEveryLevel) {
  for (const int colormap : {cv::COLORMAP_VIRIDIS, cv::COLORMAP_TURBO})
    for (int level = 0; level < 256; ++level)
      EXPECT_EQ(ColourMapColour(colormap, level / 255.0), OpenCvColour(colormap, level)) << colormap << " " << level;
}

TEST(ColourMapColour, ClampsOutOfRangeAndNanToTheEnds) {
  EXPECT_EQ(ColourMapColour(cv::COLORMAP_VIRIDIS, -3.0), OpenCvColour(cv::COLORMAP_VIRIDIS, 0));
  EXPECT_EQ(ColourMapColour(cv::COLORMAP_VIRIDIS, 7.0), OpenCvColour(cv::COLORMAP_VIRIDIS, 255));
  EXPECT_EQ(ColourMapColour(cv::COLORMAP_VIRIDIS, std::nan("")), OpenCvColour(cv::COLORMAP_VIRIDIS, 0));
  // Levels round to nearest: 0.502 * 255 = 128.01.
  EXPECT_EQ(ColourMapColour(cv::COLORMAP_TURBO, 0.502), OpenCvColour(cv::COLORMAP_TURBO, 128));
}

}  // namespace
}  // namespace omnical

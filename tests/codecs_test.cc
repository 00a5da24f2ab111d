// Image files through the codecs plugin (model/io/codecs/image_codecs.h): nothing of
// OpenCV's imgcodecs or videoio is in the process until a file is read or written, then
// the plugin reads and writes as OpenCV does.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "model/io/codecs/image_codecs.h"

namespace omnical {
namespace {

std::string MappedLibraries() {
  std::ifstream maps("/proc/self/maps");
  std::stringstream text;
  text << maps.rdbuf();
  return text.str();
}

// One test: the first-use check must run before anything else loads the plugin.
TEST(Codecs, LoadOnFirstUseAndReadWriteAsOpenCvDoes) {
  const std::string before = MappedLibraries();
  ASSERT_FALSE(before.empty());
  EXPECT_EQ(before.find("libopencv_imgcodecs"), std::string::npos);
  EXPECT_EQ(before.find("libopencv_videoio"), std::string::npos);
  EXPECT_EQ(before.find("libomnical_codecs_plugin"), std::string::npos);

  // A bundled render: 1000 x 1000, 8-bit grey (as Python's cv2.imread reads it).
  const cv::Mat grey = LoadImageFile(OMNICAL_SOURCE_DIR "/datasets-synthetic/rendered/ohte-sph-near/near000.png",
                                     cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(grey.empty());
  EXPECT_EQ(grey.cols, 1000);
  EXPECT_EQ(grey.rows, 1000);
  EXPECT_EQ(grey.type(), CV_8UC1);
  const std::string after = MappedLibraries();
  EXPECT_NE(after.find("libomnical_codecs_plugin"), std::string::npos);
  EXPECT_NE(after.find("libopencv_imgcodecs"), std::string::npos);

  // PNG is lossless: a small colour image comes back bit for bit.
  cv::Mat colour(5, 7, CV_8UC3);
  cv::randu(colour, 0, 256);
  std::vector<unsigned char> bytes;
  ASSERT_TRUE(EncodeImage(".png", colour, &bytes, {cv::IMWRITE_PNG_COMPRESSION, 9}));
  const std::string path = ::testing::TempDir() + "/codecs_test.png";
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  const cv::Mat back = LoadImageFile(path, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(back.type(), CV_8UC3);
  EXPECT_EQ(cv::norm(back, colour, cv::NORM_INF), 0.0);
  std::remove(path.c_str());

  EXPECT_TRUE(LoadImageFile(::testing::TempDir() + "/no-such-image.png", cv::IMREAD_GRAYSCALE).empty());
  EXPECT_THROW(EncodeImage(".not-an-image-format", colour, &bytes), cv::Exception);
  EXPECT_EQ(OpenVideoFile(::testing::TempDir() + "/no-such-video.avi"), nullptr);
}

// OpenCV's codes, as its documentation spells them: MJPG = 0x47504a4d, mp4v = 0x7634706d.
TEST(Codecs, FourccPacksTheCharactersLowByteFirst) {
  EXPECT_EQ(VideoFourcc('M', 'J', 'P', 'G'), 0x47504a4d);
  EXPECT_EQ(VideoFourcc('m', 'p', '4', 'v'), 0x7634706d);
}

}  // namespace
}  // namespace omnical

// What libomnical_codecs_plugin.so hands the loader (image_codecs.cc): one table of entry
// points, built by the same compiler and against the same OpenCV as the code calling it.
// The version changes with the table's layout, and the build names omnical's version, the
// compiler, OpenCV and the build tree (CMake: OMNICAL_CODECS_BUILD_ID), so a plugin of
// another table or another build, found first, is skipped. The build id sits in the
// plugin's file after kCodecsPluginMarker, where the loader reads it before loading.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "model/io/codecs/image_codecs.h"

namespace omnical {

constexpr int kCodecsPluginTableVersion = 2;
constexpr char kCodecsPluginMarker[] = "omnical codecs plugin build: ";
constexpr char kCodecsPluginBuild[] = "omnical codecs plugin build: " OMNICAL_CODECS_BUILD_ID;

struct CodecsPluginTable {
  int version;  // first in every version, so an older table is recognised
  const char* build;  // kCodecsPluginBuild
  cv::Mat (*load_image)(const std::string& path, int imread_flags);
  bool (*encode_image)(const std::string& extension, const cv::Mat& image, std::vector<unsigned char>* bytes,
                       const std::vector<int>& imwrite_params);
  std::unique_ptr<VideoFrameReader> (*open_video)(const std::string& path);
  std::unique_ptr<VideoFrameWriter> (*create_video)(const std::string& path, int fourcc, double frames_per_second,
                                                    cv::Size frame_size_px, bool colour);
};

}  // namespace omnical

// The plugin's one exported symbol.
extern "C" const omnical::CodecsPluginTable* omnical_codecs_plugin_table();

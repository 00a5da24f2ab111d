// Remap tables on disk, for the three kinds of users the correction issue names:
//  - OpenCV: float maps (CV_32FC1 "map_x", "map_y") in a cv::FileStorage file, and the
//    fixed-point pair cv::convertMaps makes (CV_16SC2 "map1", CV_16UC1 "map2") for
//    cv::remap at full speed;
//  - ffmpeg: the binary 16-bit PGM xmap/ymap its remap filter reads (integer pixels:
//    rounded; pixels that see no mirror get 65535, beyond any frame, which the filter fills);
//  - NumPy: float32 .npy arrays (format 1.0), shape (height, width), -1 where invalid.
// Every file is written to a temporary name and renamed into place.
#pragma once

#include <string>

#include "correction/remap_table.h"

namespace omnical {

void WriteOpenCvMaps(const RemapTable& table, const std::string& float_path, const std::string& fixed_path);
void WriteFfmpegMaps(const RemapTable& table, const std::string& xmap_path, const std::string& ymap_path);
void WriteNpyMaps(const RemapTable& table, const std::string& x_path, const std::string& y_path);

// Reads the float maps back; throws InputError naming the file (unreadable, missing or
// mismatched maps).
RemapTable ReadOpenCvMaps(const std::string& float_path);

}  // namespace omnical

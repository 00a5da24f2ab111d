#include "correction/map_export.h"

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>

#include "model/io/atomic_write.h"
#include "model/input_error.h"

namespace omnical {
namespace {

cv::Mat MapMat(const RemapTable& table, const std::vector<float>& values) {
  return cv::Mat(table.height, table.width, CV_32F, const_cast<float*>(values.data()));
}

void WriteFileStorageAtomically(const std::string& path, const std::function<void(cv::FileStorage&)>& write) {
  WriteFileAtomicallyByPath(path, [&](const std::string& temporary) {
    try {
      cv::FileStorage storage(temporary, cv::FileStorage::WRITE);
      if (!storage.isOpened()) throw InputError(InputMessage(path, "", "cannot be written"));
      write(storage);
      storage.release();
    } catch (const cv::Exception& e) {
      throw InputError(InputMessage(path, "", std::string("cannot be written: ") + e.err));
    }
  });
}

void WritePgm16(const RemapTable& table, const std::vector<float>& values, const std::string& path) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "P5\n" << table.width << ' ' << table.height << "\n65535\n";
    std::vector<unsigned char> bytes(2 * values.size());
    for (size_t i = 0; i < values.size(); ++i) {
      const float value = values[i];
      const long rounded = value < -0.5f ? 65535L : std::lround(value);  // -1: no mirror
      const uint16_t word = static_cast<uint16_t>(std::min(65535L, std::max(0L, rounded)));
      bytes[2 * i] = static_cast<unsigned char>(word >> 8);  // PGM is big-endian
      bytes[2 * i + 1] = static_cast<unsigned char>(word & 0xff);
    }
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  });
}

void WriteNpyFloat32(const RemapTable& table, const std::vector<float>& values, const std::string& path) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    std::string header = "{'descr': '<f4', 'fortran_order': False, 'shape': (" + std::to_string(table.height) + ", " +
                         std::to_string(table.width) + "), }";
    // Magic (6) + version (2) + length (2) + header + '\n' padded to a multiple of 64.
    const size_t unpadded = 10 + header.size() + 1;
    header.append((64 - unpadded % 64) % 64, ' ');
    header += '\n';
    out.write("\x93NUMPY\x01\x00", 8);
    const uint16_t length = static_cast<uint16_t>(header.size());
    const char length_bytes[2] = {static_cast<char>(length & 0xff), static_cast<char>(length >> 8)};
    out.write(length_bytes, 2);
    out << header;
    static_assert(sizeof(float) == 4, "float32");
    for (float value : values) {  // little-endian, whatever the host
      uint32_t bits;
      std::memcpy(&bits, &value, 4);
      const char b[4] = {char(bits & 0xff), char((bits >> 8) & 0xff), char((bits >> 16) & 0xff), char(bits >> 24)};
      out.write(b, 4);
    }
  });
}

}  // namespace

void WriteOpenCvMaps(const RemapTable& table, const std::string& float_path, const std::string& fixed_path) {
  const cv::Mat map_x = MapMat(table, table.map_x), map_y = MapMat(table, table.map_y);
  WriteFileStorageAtomically(float_path, [&](cv::FileStorage& fs) {
    fs << "map_x" << map_x << "map_y" << map_y;
  });
  cv::Mat map1, map2;
  cv::convertMaps(map_x, map_y, map1, map2, CV_16SC2);
  WriteFileStorageAtomically(fixed_path, [&](cv::FileStorage& fs) { fs << "map1" << map1 << "map2" << map2; });
}

void WriteFfmpegMaps(const RemapTable& table, const std::string& xmap_path, const std::string& ymap_path) {
  WritePgm16(table, table.map_x, xmap_path);
  WritePgm16(table, table.map_y, ymap_path);
}

void WriteNpyMaps(const RemapTable& table, const std::string& x_path, const std::string& y_path) {
  WriteNpyFloat32(table, table.map_x, x_path);
  WriteNpyFloat32(table, table.map_y, y_path);
}

}  // namespace omnical

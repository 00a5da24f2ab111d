#include "calib/image_file.h"

#include <glob.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>

#include "model/input_error.h"
#include "model/io/codecs/image_codecs.h"

namespace omnical {

std::vector<std::string> ListImages(const std::string& where) {
  std::vector<std::string> paths;
  if (std::filesystem::is_directory(where)) {
    for (const auto& entry : std::filesystem::directory_iterator(where)) {
      std::string extension = entry.path().extension().string();
      std::transform(extension.begin(), extension.end(), extension.begin(), ::tolower);
      if (extension == ".png" || extension == ".pgm" || extension == ".jpg" || extension == ".jpeg" ||
          extension == ".tif" || extension == ".tiff" || extension == ".bmp")
        paths.push_back(entry.path().string());
    }
  } else {
    glob_t matches;
    if (::glob(where.c_str(), 0, nullptr, &matches) == 0)
      for (size_t i = 0; i < matches.gl_pathc; ++i) paths.push_back(matches.gl_pathv[i]);
    ::globfree(&matches);
  }
  std::sort(paths.begin(), paths.end());
  if (paths.empty()) throw InputError(InputMessage(where, "images", "no images found (a directory or a glob pattern)"));
  return paths;
}

cv::Mat ReadImageFile(const std::string& path, int flags) {
  std::string extension = path.size() >= 4 ? path.substr(path.size() - 4) : "";
  std::transform(extension.begin(), extension.end(), extension.begin(), [](unsigned char c) { return std::tolower(c); });
  if (extension == ".png") {
    // A PNG ends with the 12-byte IEND chunk: length 0, "IEND", its CRC.
    static const char kIend[] = {0, 0, 0, 0, 'I', 'E', 'N', 'D', '\xae', 'B', '`', '\x82'};
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    char tail[12] = {};
    if (!in || in.tellg() < 12 || !in.seekg(-12, std::ios::end) || !in.read(tail, 12) ||
        !std::equal(tail, tail + 12, kIend))
      return cv::Mat();
  }
  return LoadImageFile(path, flags);
}

}  // namespace omnical

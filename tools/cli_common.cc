#include "tools/cli_common.h"

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <iostream>

#include "model/atomic_write.h"

namespace omnical::cli {

void WriteOutput(const std::string& path, const std::function<void(std::ostream&)>& write) {
  if (path.empty() || path == "-") {
    write(std::cout);
    std::cout.flush();
    return;
  }
  WriteFileAtomically(path, write);
}

cv::Mat ReadImage(const std::string& path, int flags) {
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
  return cv::imread(path, flags);
}

}  // namespace omnical::cli

#include "tools/cli_common.h"

#include <cstdio>
#include <iostream>

#include "calib/image_file.h"
#include "model/io/atomic_write.h"

namespace omnical::cli {

void WriteOutput(const std::string& path, const std::function<void(std::ostream&)>& write) {
  if (path.empty() || path == "-") {
    write(std::cout);
    std::cout.flush();
    return;
  }
  WriteFileAtomically(path, write);
}

cv::Mat ReadImage(const std::string& path, int flags) { return ReadImageFile(path, flags); }

void PrintWarnings(const std::vector<CalibrationWarning>& warnings, const Context& context) {
  for (const CalibrationWarning& w : warnings)
    if (!context.quiet || w.code != WarningCode::kViewSkipped) std::fprintf(stderr, "omnical: warning: %s\n", w.text.c_str());
}

}  // namespace omnical::cli

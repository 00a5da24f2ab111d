#include "tools/cli_common.h"

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

}  // namespace omnical::cli

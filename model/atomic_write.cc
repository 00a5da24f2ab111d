#include "model/atomic_write.h"

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "model/input_error.h"

namespace omnical {

void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  const std::string temp_path = path + ".tmp." + std::to_string(::getpid());
  {
    std::ofstream stream(temp_path, std::ios::binary | std::ios::trunc);
    if (!stream) throw InputError(InputMessage(path, "", "cannot create output file"));
    try {
      write(stream);
    } catch (...) {
      stream.close();
      std::remove(temp_path.c_str());
      throw;
    }
    stream.flush();
    if (!stream) {
      stream.close();
      std::remove(temp_path.c_str());
      throw InputError(InputMessage(path, "", "write failed (disk full?)"));
    }
  }
  std::error_code error;
  std::filesystem::rename(temp_path, path, error);
  if (error) {
    std::remove(temp_path.c_str());
    throw InputError(InputMessage(path, "", "cannot rename into place: " + error.message()));
  }
}

void WriteFileAtomicallyByPath(const std::string& path, const std::function<void(const std::string&)>& write) {
  const std::filesystem::path target(path);
  const std::string temp_path =
      (target.parent_path() / (".tmp" + std::to_string(::getpid()) + "-" + target.filename().string())).string();
  try {
    write(temp_path);
  } catch (...) {
    std::remove(temp_path.c_str());
    throw;
  }
  std::error_code error;
  std::filesystem::rename(temp_path, path, error);
  if (error) {
    std::remove(temp_path.c_str());
    throw InputError(InputMessage(path, "", "cannot rename into place: " + error.message()));
  }
}

}  // namespace omnical

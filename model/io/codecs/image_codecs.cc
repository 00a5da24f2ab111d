#include "model/io/codecs/image_codecs.h"

#include <dlfcn.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <mutex>

#include "model/input_error.h"
#include "model/io/codecs/codecs_plugin_table.h"

namespace omnical {
namespace {

constexpr char kPluginFile[] = "libomnical_codecs_plugin.so";

// Where the plugin may be, first found first: OMNICAL_CODECS_PLUGIN; beside the program or
// module that holds this code, in <libdir>/omnical up to four directories above it (the
// build tree: <build>/tools/omnical, <build>/tests/bench/*, <build>/python/omnical/;
// installed: <prefix>/bin/omnical, the Python package in <prefix>/lib/python3/...); the
// install directory; the build tree this code was built in (a program linking an installed
// omnical from elsewhere, before or without its install); then the loader's own search.
std::vector<std::string> PluginCandidates() {
  std::vector<std::string> candidates;
  if (const char* named = std::getenv("OMNICAL_CODECS_PLUGIN"); named && *named) candidates.push_back(named);
  // The program's own directory (for the main program dladdr gives only argv[0], perhaps
  // relative to a directory since left), and that of the module holding this code where it
  // is another (the Python extension, loaded by its absolute path).
  std::vector<std::filesystem::path> directories;
  std::error_code error;
  const std::filesystem::path program = std::filesystem::read_symlink("/proc/self/exe", error);
  if (!error) directories.push_back(program.parent_path());
  Dl_info info{};
  if (::dladdr(reinterpret_cast<void*>(&PluginCandidates), &info) != 0 && info.dli_fname != nullptr &&
      info.dli_fname[0] == '/') {
    const std::filesystem::path module = std::filesystem::path(info.dli_fname).parent_path();
    if (directories.empty() || module != directories.front()) directories.push_back(module);
  }
  for (const std::filesystem::path& directory : directories) {
    std::filesystem::path up = directory;
    for (int level = 0; level <= 4; ++level, up /= "..")
      candidates.push_back((up / OMNICAL_CODECS_LIBDIR / "omnical" / kPluginFile).lexically_normal().string());
  }
  candidates.push_back(OMNICAL_CODECS_INSTALL_DIR "/" + std::string(kPluginFile));
  candidates.push_back(OMNICAL_CODECS_BUILD_DIR "/" + std::string(kPluginFile));
  candidates.push_back(kPluginFile);
  // Directories above / collapse to the same path: each tried once, in order.
  std::vector<std::string> unique;
  for (const std::string& candidate : candidates)
    if (std::find(unique.begin(), unique.end(), candidate) == unique.end()) unique.push_back(candidate);
  return unique;
}

const CodecsPluginTable& Plugin() {
  static const CodecsPluginTable* table = nullptr;
  static std::string failure;
  static std::once_flag once;
  std::call_once(once, [] {
    std::string tried;
    for (const std::string& candidate : PluginCandidates()) {
      // Never closed: the codecs stay for the process's life, as linked ones would.
      void* handle = ::dlopen(candidate.c_str(), RTLD_NOW | RTLD_LOCAL);
      if (handle == nullptr) {
        tried += (tried.empty() ? "" : ", ") + candidate;
        continue;
      }
      using Entry = const CodecsPluginTable* (*)();
      const auto entry = reinterpret_cast<Entry>(::dlsym(handle, "omnical_codecs_plugin_table"));
      const CodecsPluginTable* found = entry != nullptr ? entry() : nullptr;
      if (found != nullptr && found->version == kCodecsPluginTableVersion) {
        table = found;
        return;
      }
      tried += (tried.empty() ? "" : ", ") + candidate + " (another version)";
    }
    // A missing file of the installation, named with the variable that points at it: an
    // InputError, so the CLI exits 2 and Python raises omnical.InputError, as for any file.
    failure = InputMessage("OMNICAL_CODECS_PLUGIN", "", std::string(kPluginFile) +
                                                        " (omnical's image and video file support) not found; tried " +
                                                        tried + "; set OMNICAL_CODECS_PLUGIN to its path");
  });
  if (table == nullptr) throw InputError(failure);
  return *table;
}

}  // namespace

cv::Mat LoadImageFile(const std::string& path, int imread_flags) { return Plugin().load_image(path, imread_flags); }

bool EncodeImage(const std::string& extension, const cv::Mat& image, std::vector<unsigned char>* bytes,
                 const std::vector<int>& imwrite_params) {
  return Plugin().encode_image(extension, image, bytes, imwrite_params);
}

std::unique_ptr<VideoFrameReader> OpenVideoFile(const std::string& path) { return Plugin().open_video(path); }

std::unique_ptr<VideoFrameWriter> CreateVideoFile(const std::string& path, int fourcc, double frames_per_second,
                                                  cv::Size frame_size, bool colour) {
  return Plugin().create_video(path, fourcc, frames_per_second, frame_size, colour);
}

}  // namespace omnical

#include "model/io/codecs/image_codecs.h"

#include <dlfcn.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <mutex>

#include "model/input_error.h"
#include "model/io/codecs/codecs_plugin_table.h"

namespace omnical {
namespace {

#ifndef OMNICAL_CODECS_PYTHON_PACKAGE_DIR  // built without the Python module
#define OMNICAL_CODECS_PYTHON_PACKAGE_DIR ""
#endif

constexpr char kPluginFile[] = "libomnical_codecs_plugin.so";

// `directory` less its trailing `suffix` (relative, e.g. "bin" or
// "lib/python3/dist-packages/omnical"), or empty when it does not end so.
std::filesystem::path PrefixEndingIn(const std::filesystem::path& directory, const std::filesystem::path& suffix) {
  if (suffix.empty() || suffix.is_absolute()) return {};
  std::filesystem::path prefix = directory;
  std::vector<std::filesystem::path> tail(suffix.begin(), suffix.end());
  for (auto part = tail.rbegin(); part != tail.rend(); ++part) {
    if (prefix.filename() != *part || !prefix.has_relative_path()) return {};
    prefix = prefix.parent_path();
  }
  return prefix;
}

// Where the plugin may be when OMNICAL_CODECS_PLUGIN is not set, first found first. For the
// module holding this code (the Python extension, or the
// program) and then the program itself: when it sits where `cmake --install` puts it
// (<prefix>/bin, or the Python package's directory), <prefix>/<libdir>/omnical, so a
// relocated install finds its own plugin; then the loader's search by name (LD_LIBRARY_PATH,
// and the RUNPATH omnical's CMake package gives programs linking an installed omnical); then
// the configured install directory, then the build tree this code was built in. Only these:
// no directory above an arbitrary program's (such as /tmp/lib) is ever tried.
std::vector<std::string> PluginCandidates() {
  std::vector<std::filesystem::path> directories;
  // dladdr names the main program only as argv[0], perhaps relative to a directory since
  // left: a relative answer is not used, /proc/self/exe covers the program.
  Dl_info info{};
  if (::dladdr(reinterpret_cast<void*>(&PluginCandidates), &info) != 0 && info.dli_fname != nullptr &&
      info.dli_fname[0] == '/')
    directories.push_back(std::filesystem::path(info.dli_fname).parent_path());
  std::error_code error;
  const std::filesystem::path program = std::filesystem::read_symlink("/proc/self/exe", error);
  if (!error) directories.push_back(program.parent_path());
  std::vector<std::string> candidates;
  for (const std::filesystem::path& directory : directories) {
    for (const char* layout : {OMNICAL_CODECS_BINDIR, OMNICAL_CODECS_PYTHON_PACKAGE_DIR}) {
      const std::filesystem::path prefix = PrefixEndingIn(directory.lexically_normal(), layout);
      if (!prefix.empty())
        candidates.push_back((prefix / OMNICAL_CODECS_LIBDIR / "omnical" / kPluginFile).lexically_normal().string());
    }
  }
  candidates.push_back(kPluginFile);
  candidates.push_back(OMNICAL_CODECS_INSTALL_DIR "/" + std::string(kPluginFile));
  candidates.push_back(OMNICAL_CODECS_BUILD_DIR "/" + std::string(kPluginFile));
  std::vector<std::string> unique;  // each tried once, in order
  for (const std::string& candidate : candidates)
    if (std::find(unique.begin(), unique.end(), candidate) == unique.end()) unique.push_back(candidate);
  return unique;
}

// The table of the plugin at `candidate`, or null with `why` saying what was wrong (empty
// when there is no such file); a plugin that is not used is closed again.
const CodecsPluginTable* OpenPlugin(const std::string& candidate, std::string* why) {
  void* handle = ::dlopen(candidate.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) {
    const char* loader_error = ::dlerror();
    // "No such file" is the ordinary miss; anything else (a plugin that exists but does not
    // load) is worth the loader's own words.
    const bool missing = loader_error == nullptr || std::strstr(loader_error, "No such file") != nullptr;
    *why = missing ? "" : loader_error;
    if (why->rfind(candidate + ": ", 0) == 0) why->erase(0, candidate.size() + 2);  // named already
    return nullptr;
  }
  using Entry = const CodecsPluginTable* (*)();
  const auto entry = reinterpret_cast<Entry>(::dlsym(handle, "omnical_codecs_plugin_table"));
  const CodecsPluginTable* table = entry != nullptr ? entry() : nullptr;
  if (table == nullptr) {
    *why = "not an omnical codecs plugin";
  } else if (table->version != kCodecsPluginTableVersion || std::strcmp(table->build, kCodecsPluginBuild) != 0) {
    // The table's layout and the std::string, cv::Mat it passes are only known to agree
    // with a plugin of this very build.
    *why = std::string("from another build (") + (table->version == kCodecsPluginTableVersion ? table->build : "older") +
           "; this program's: " + kCodecsPluginBuild + ")";
    table = nullptr;
  } else {
    return table;  // never closed: the codecs stay for the process's life, as linked ones would
  }
  ::dlclose(handle);
  return nullptr;
}

const CodecsPluginTable& Plugin() {
  static const CodecsPluginTable* table = nullptr;
  static std::string failure;
  static std::once_flag once;
  std::call_once(once, [] {
    // A missing or wrong file of the installation is bad input named by the variable that
    // points at it: an InputError, so the CLI exits 2 and Python raises omnical.InputError.
    if (const char* named = std::getenv("OMNICAL_CODECS_PLUGIN"); named && *named) {
      std::string why;
      table = OpenPlugin(named, &why);
      if (table == nullptr)
        failure = InputMessage("OMNICAL_CODECS_PLUGIN", named,
                               (why.empty() ? "no such file" : why) + "; it must name " + kPluginFile +
                                   " (omnical's image and video file support) of this build, or be unset");
      return;
    }
    std::string tried;
    for (const std::string& candidate : PluginCandidates()) {
      std::string why;
      table = OpenPlugin(candidate, &why);
      if (table != nullptr) return;
      tried += (tried.empty() ? "" : ", ") + candidate + (why.empty() ? "" : " (" + why + ")");
    }
    failure = InputMessage("OMNICAL_CODECS_PLUGIN", "",
                           std::string(kPluginFile) + " (omnical's image and video file support) not loaded; tried " +
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
                                                  cv::Size frame_size_px, bool colour) {
  return Plugin().create_video(path, fourcc, frames_per_second, frame_size_px, colour);
}

}  // namespace omnical

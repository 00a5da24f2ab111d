#include "model/io/codecs/image_codecs.h"

#include <dlfcn.h>
#include <link.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
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
  std::vector<std::filesystem::path> tail;
  for (const std::filesystem::path& part : suffix.lexically_normal())
    if (!part.empty() && part != ".") tail.push_back(part);
  if (tail.empty() || std::find(tail.begin(), tail.end(), "..") != tail.end()) return {};
  std::filesystem::path prefix = directory.lexically_normal();
  if (prefix.filename().empty()) prefix = prefix.parent_path();  // a trailing separator
  for (auto part = tail.rbegin(); part != tail.rend(); ++part) {
    if (prefix.filename() != *part || !prefix.has_relative_path()) return {};
    prefix = prefix.parent_path();
  }
  return prefix;
}

bool IsUnder(const std::filesystem::path& path, const std::filesystem::path& directory) {
  const std::filesystem::path relative = path.lexically_relative(directory);
  return !relative.empty() && *relative.begin() != "..";
}

// The directories omnical's code runs from: the module holding this code when it is not
// the main program (the Python extension), then the main program's. dladdr names the main
// program as argv[0], which its caller chooses, so the link map tells it apart (an empty
// name) and /proc/self/exe, the file really run, stands for it.
std::vector<std::filesystem::path> CodeDirectories() {
  std::vector<std::filesystem::path> directories;
  Dl_info info{};
  link_map* module = nullptr;
  if (::dladdr1(reinterpret_cast<void*>(&CodeDirectories), &info, reinterpret_cast<void**>(&module),
                RTLD_DL_LINKMAP) != 0 &&
      module != nullptr && module->l_name != nullptr && module->l_name[0] == '/') {
    std::error_code error;
    const std::filesystem::path file = std::filesystem::canonical(module->l_name, error);
    if (!error) directories.push_back(file.parent_path());
  }
  std::error_code error;
  const std::filesystem::path program = std::filesystem::read_symlink("/proc/self/exe", error);
  if (!error) directories.push_back(program.parent_path());
  return directories;
}

// Where the plugin may be when OMNICAL_CODECS_PLUGIN is not set, first found first. For
// each code directory (above): the build tree's plugin when the code lies in the build
// tree it was built in (tests, the CLI and the Python package before install); <prefix>/
// <libdir>/omnical when it sits where `cmake --install` puts it (<prefix>/bin, or the
// Python package's directory), so a moved prefix finds its own plugin. Then the loader's
// search by name (LD_LIBRARY_PATH, and the RUNPATH omnical's CMake package gives programs
// linking an installed omnical), then the configured install directory.
std::vector<std::string> PluginCandidates(const std::vector<std::filesystem::path>& code_directories) {
  std::vector<std::string> candidates;
  std::error_code error;
  const std::filesystem::path build_tree = std::filesystem::weakly_canonical(OMNICAL_CODECS_BUILD_TREE, error);
  for (const std::filesystem::path& directory : code_directories) {
    if (!error && IsUnder(directory, build_tree)) candidates.push_back(OMNICAL_CODECS_BUILD_DIR "/" + std::string(kPluginFile));
    for (const char* layout : {OMNICAL_CODECS_BINDIR, OMNICAL_CODECS_PYTHON_PACKAGE_DIR}) {
      const std::filesystem::path prefix = PrefixEndingIn(directory, layout);
      if (!prefix.empty())
        candidates.push_back((prefix / OMNICAL_CODECS_LIBDIR / "omnical" / kPluginFile).lexically_normal().string());
    }
  }
  candidates.push_back(kPluginFile);
  candidates.push_back(OMNICAL_CODECS_INSTALL_DIR "/" + std::string(kPluginFile));
  std::vector<std::string> unique;  // each tried once, in order
  for (const std::string& candidate : candidates)
    if (std::find(unique.begin(), unique.end(), candidate) == unique.end()) unique.push_back(candidate);
  return unique;
}

// Who may own a plugin found by searching: root, this user and the owners of the code
// directories (whoever installed omnical).
std::vector<uid_t> TrustedOwners(const std::vector<std::filesystem::path>& code_directories) {
  std::vector<uid_t> trusted = {0, ::geteuid()};
  struct stat status {};
  for (const std::filesystem::path& directory : code_directories)
    if (::stat(directory.c_str(), &status) == 0) trusted.push_back(status.st_uid);
  return trusted;
}

// Whether a plugin found by searching may be loaded: the file and its directory belong to
// a trusted owner and others cannot write them. A directory anyone can create (such as
// /tmp/lib) then offers nothing to load.
std::string UntrustedWhy(const std::string& path, const std::vector<uid_t>& trusted) {
  struct stat status {};
  for (const std::string& checked : {path, std::filesystem::path(path).parent_path().string()}) {
    if (::stat(checked.c_str(), &status) != 0) return "cannot stat " + checked;
    if (std::find(trusted.begin(), trusted.end(), status.st_uid) == trusted.end())
      return "not loaded: " + checked + " belongs to uid " + std::to_string(status.st_uid);
    if (status.st_mode & S_IWOTH) return "not loaded: others may write " + checked;
  }
  return {};
}

// The build id the plugin file at `path` carries (kCodecsPluginBuild, after its marker), or
// empty without one. Read from the file, before it is loaded: loading a plugin runs the
// initialisers of the ~240 libraries it brings, which unloading it again does not undo.
// Should the compiler keep the marker on its own as well, this build's id is still found
// among the others.
std::string BuildIdInFile(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  std::string found;
  for (size_t at = bytes.find(kCodecsPluginMarker); at != std::string::npos;
       at = bytes.find(kCodecsPluginMarker, at + 1)) {
    const std::string id = bytes.c_str() + at;  // up to its terminating NUL
    if (id == kCodecsPluginBuild) return id;
    if (id.size() > found.size()) found = id;
  }
  return found;
}

// Why a plugin of build `build` (its id with the marker) is refused: the table passes
// std::string and cv::Mat across, and only a plugin of this very build is known to agree.
std::string AnotherBuild(const std::string& build) {
  const size_t marker = std::strlen(kCodecsPluginMarker);
  return "from another build (" + build.substr(std::min(marker, build.size())) +
         "; this program's: " + std::string(kCodecsPluginBuild + marker) + ")";
}

// The table of the plugin at `candidate` (a path, or the bare name for the loader's own
// search), or null with `why` saying what was wrong: empty when there is no such file.
// `trusted`: the owners a plugin found by searching may have; null for a file the user named.
const CodecsPluginTable* OpenPlugin(const std::string& candidate, const std::vector<uid_t>* trusted, std::string* why) {
  if (candidate.find('/') != std::string::npos) {
    struct stat status {};
    if (::stat(candidate.c_str(), &status) != 0) return nullptr;  // not there
    if (trusted != nullptr && !(*why = UntrustedWhy(candidate, *trusted)).empty()) return nullptr;
    // The plugin is ~20 KB (a debug build's under a MB): a file far larger is not read.
    const std::string build = status.st_size < (64 << 20) ? BuildIdInFile(candidate) : std::string();
    if (build.empty()) {
      *why = "not an omnical codecs plugin";
      return nullptr;
    }
    if (build != kCodecsPluginBuild) {
      *why = AnotherBuild(build);
      return nullptr;
    }
  }
  void* handle = ::dlopen(candidate.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) {
    const char* loader_error = ::dlerror();
    std::string text = loader_error != nullptr ? loader_error : "cannot be loaded";
    if (text.rfind(candidate + ": ", 0) == 0) {
      text.erase(0, candidate.size() + 2);  // named already
      if (text.find("No such file") != std::string::npos) text.clear();  // the file itself: not there
    }
    *why = text;  // otherwise a library it needs, or a file that is no plugin
    return nullptr;
  }
  // Found by the loader's search, the file was not read first: the table says the same.
  // A refused plugin stays loaded: closing it again is not safe once its libraries ran.
  using Entry = const CodecsPluginTable* (*)();
  const auto entry = reinterpret_cast<Entry>(::dlsym(handle, "omnical_codecs_plugin_table"));
  const CodecsPluginTable* table = entry != nullptr ? entry() : nullptr;
  if (table == nullptr) {
    *why = "not an omnical codecs plugin";
  } else if (table->version != kCodecsPluginTableVersion) {
    *why = "from another build (entry table version " + std::to_string(table->version) + ", this program's " +
           std::to_string(kCodecsPluginTableVersion) + ")";
  } else if (std::strcmp(table->build, kCodecsPluginBuild) != 0) {
    *why = AnotherBuild(table->build);
  } else {
    return table;  // kept for the process's life, as linked codecs would be
  }
  return nullptr;
}

const CodecsPluginTable& Plugin() {
  static const CodecsPluginTable* table = nullptr;
  static std::string failure;
  static std::once_flag once;
  std::call_once(once, [] {
    // A missing or wrong file of the installation is bad input named by the variable that
    // points at it: an InputError, so the CLI exits 2 and Python raises omnical.InputError.
    if (const char* named = ::secure_getenv("OMNICAL_CODECS_PLUGIN"); named && *named) {
      // A file, even without a directory: not a name for the loader's search.
      const std::string path = std::strchr(named, '/') != nullptr ? named : std::string("./") + named;
      std::string why;
      table = OpenPlugin(path, nullptr, &why);
      if (table == nullptr)
        failure = InputMessage("OMNICAL_CODECS_PLUGIN", named,
                               (why.empty() ? "no such file" : why) + "; it must name " + kPluginFile +
                                   " (omnical's image and video file support) of this build, or be unset");
      return;
    }
    const std::vector<std::filesystem::path> code_directories = CodeDirectories();
    const std::vector<uid_t> trusted = TrustedOwners(code_directories);
    std::string tried;
    for (const std::string& candidate : PluginCandidates(code_directories)) {
      std::string why;
      table = OpenPlugin(candidate, &trusted, &why);
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

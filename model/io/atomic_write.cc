#include "model/io/atomic_write.h"

#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>

#include "model/input_error.h"

namespace omnical {
namespace {

// The temporary files being written now, for the interrupt handler: fixed storage, since
// a signal handler may only read memory and call async-signal-safe functions (unlink).
constexpr int kSlots = 32;
constexpr size_t kPathBytes = 4096;
char temp_paths[kSlots][kPathBytes];
volatile std::sig_atomic_t slot_used[kSlots];
std::mutex slots_mutex;

// Registers a temporary file for the life of the scope (no slot: not removed on interrupt,
// which only leaves a stray file, never a wrong result).
class InFlight {
 public:
  explicit InFlight(const std::string& path) {
    if (path.size() >= kPathBytes) return;
    std::lock_guard<std::mutex> lock(slots_mutex);
    for (int i = 0; i < kSlots; ++i) {
      if (slot_used[i]) continue;
      std::memcpy(temp_paths[i], path.c_str(), path.size() + 1);
      slot_ = i;
      slot_used[i] = 1;
      return;
    }
  }
  ~InFlight() {
    if (slot_ < 0) return;
    std::lock_guard<std::mutex> lock(slots_mutex);
    slot_used[slot_] = 0;
  }
  InFlight(const InFlight&) = delete;
  InFlight& operator=(const InFlight&) = delete;

 private:
  int slot_ = -1;
};

extern "C" void RemoveInFlightAndDie(int signal_number) { RemoveTemporaryFilesAndDie(signal_number); }

}  // namespace

void RemoveTemporaryFilesAndDie(int signal_number) {
  for (int i = 0; i < kSlots; ++i)
    if (slot_used[i]) ::unlink(temp_paths[i]);
  std::signal(signal_number, SIG_DFL);
  std::raise(signal_number);
}

void RemoveTemporaryFilesOnInterrupt() {
  for (int signal_number : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction action {};
    action.sa_handler = RemoveInFlightAndDie;
    sigemptyset(&action.sa_mask);
    sigaction(signal_number, &action, nullptr);
  }
}

void CreateOutputDirectory(const std::string& dir) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error || !std::filesystem::is_directory(dir))
    throw InputError(InputMessage(dir, "", "cannot create output directory" + (error ? " (" + error.message() + ")" : std::string())));
}

void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  const std::string temp_path = path + ".tmp." + std::to_string(::getpid());
  const InFlight in_flight(temp_path);
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
  const InFlight in_flight(temp_path);
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

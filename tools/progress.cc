#include "tools/progress.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <memory>
#include <mutex>
#include <string>

#include "model/io/atomic_write.h"

namespace omnical::cli {
namespace {

volatile std::sig_atomic_t interrupted = 0;

// First Ctrl-C: ask the job to stop at its next progress report (it unwinds, removing
// the temporary files it was writing). A second one, or a job that does not report:
// end now the way the signal would (model/io/atomic_write.h removes temporaries).
extern "C" void OnInterrupt(int signal_number) {
  if (interrupted) {
    RemoveTemporaryFilesAndDie(signal_number);
    return;
  }
  interrupted = 1;
}

struct Bar {
  std::mutex mutex;
  std::string stage;
  long done = -1, total = 0;
  bool open = false;  // a line drawn and not ended
  std::chrono::steady_clock::time_point last;
  ~Bar() {
    if (open) std::fputc('\n', stderr);
  }
  void Draw() {
    if (total > 0) {
      std::fprintf(stderr, "\r%s: %3d%% (%ld/%ld)", stage.c_str(), static_cast<int>(100 * std::min(done, total) / total),
                   done, total);
    } else {
      std::fprintf(stderr, "\r%s: %ld", stage.c_str(), done);  // steps of unknown number (solver iterations)
    }
    std::fflush(stderr);
    open = true;
  }
};

}  // namespace

Progress::Progress(std::string label, long total, bool quiet)
    : label_(std::move(label)), total_(total), enabled_(!quiet && ::isatty(STDERR_FILENO)) {}

Progress::~Progress() {
  if (!enabled_) return;
  Draw(total_);
  std::fputc('\n', stderr);
}

void Progress::Advance(long amount) {
  const long done = done_ += amount;
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  std::lock_guard<std::mutex> lock(mutex_);
  if (now - last_draw_ < std::chrono::milliseconds(100)) return;
  last_draw_ = now;
  Draw(done);
}

void Progress::Draw(long done) {
  const int percent = total_ > 0 ? static_cast<int>(100 * done / total_) : 100;
  std::fprintf(stderr, "\r%s: %3d%% (%ld/%ld)", label_.c_str(), percent, done, total_);
  std::fflush(stderr);
}

bool InterruptRequested() { return interrupted != 0; }

void InstallInterruptHandler() {
  struct sigaction action = {};
  action.sa_handler = OnInterrupt;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
}

ProgressCallback TerminalProgress(const Context& context) {
  const bool enabled = !context.quiet && ::isatty(STDERR_FILENO);
  auto bar = std::make_shared<Bar>();
  return [enabled, bar](const ProgressUpdate& update) {
    if (!enabled) return !InterruptRequested();
    std::lock_guard<std::mutex> lock(bar->mutex);
    const auto now = std::chrono::steady_clock::now();
    if (update.stage != bar->stage) {
      if (bar->open) std::fputc('\n', stderr);
      bar->open = false;
      bar->stage = update.stage;
      bar->done = -1;
      bar->last = {};
    }
    bar->done = std::max(bar->done, update.done), bar->total = update.total;
    const bool finished = update.total > 0 && update.done >= update.total;
    if (finished || now - bar->last >= std::chrono::milliseconds(100)) {
      bar->last = now;
      bar->Draw();
      if (finished) {
        std::fputc('\n', stderr);
        bar->open = false;
        bar->stage.clear();
        bar->done = -1;
      }
    }
    return !InterruptRequested();
  };
}

}  // namespace omnical::cli

#include "tools/progress.h"

#include <unistd.h>

#include <cstdio>
#include <memory>

namespace omnical::cli {

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

bool InterruptRequested() { return false; }

namespace {

// The bar of the stage being reported; a new stage (or a restart of the same one) ends
// the previous line, and so does the end of the job (the last copy of the callback).
class TerminalBar {
 public:
  explicit TerminalBar(bool enabled) : enabled_(enabled) {}
  ~TerminalBar() { EndLine(); }
  void Update(const ProgressUpdate& update) {
    if (!enabled_) return;
    if (open_ && (update.stage != stage_ || update.done < done_)) EndLine();
    const auto now = std::chrono::steady_clock::now();
    const bool finished = update.total > 0 && update.done >= update.total;
    if (open_ && !finished && now - last_draw_ < std::chrono::milliseconds(100)) {
      done_ = update.done;
      return;
    }
    stage_ = update.stage, done_ = update.done, last_draw_ = now, open_ = true;
    const int percent = update.total > 0 ? static_cast<int>(100 * update.done / update.total) : 100;
    std::fprintf(stderr, "\r%s: %3d%% (%ld/%ld)", update.stage.c_str(), percent, update.done, update.total);
    std::fflush(stderr);
    if (finished) EndLine();
  }

 private:
  void EndLine() {
    if (!open_) return;
    std::fputc('\n', stderr);
    open_ = false;
  }
  bool enabled_;
  bool open_ = false;
  std::string stage_;
  long done_ = 0;
  std::chrono::steady_clock::time_point last_draw_;
};

}  // namespace

ProgressCallback TerminalProgress(const Context& context) {
  auto bar = std::make_shared<TerminalBar>(!context.quiet && ::isatty(STDERR_FILENO));
  return [bar](const ProgressUpdate& update) {
    bar->Update(update);
    return !InterruptRequested();
  };
}

}  // namespace omnical::cli

#include "tools/progress.h"

#include <unistd.h>

#include <cstdio>

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

}  // namespace omnical::cli

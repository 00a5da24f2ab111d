// Progress on a terminal for long work: a single updating line on stderr, only when
// stderr is a terminal and --quiet was not given. Thread-safe.
#pragma once

#include <atomic>
#include <chrono>
#include <mutex>
#include <string>

#include "model/progress.h"
#include "tools/cli_common.h"

namespace omnical::cli {

// True once the user asked the running command to stop (Ctrl-C); library jobs are told
// through their progress callbacks.
bool InterruptRequested();

// A ProgressCallback for library jobs: the same one-line bar per stage as Progress (only
// when stderr is a terminal and --quiet was not given); returns !InterruptRequested().
ProgressCallback TerminalProgress(const Context& context);

class Progress {
 public:
  Progress(std::string label, long total, bool quiet);
  ~Progress();
  void Advance(long amount = 1);

 private:
  void Draw(long done);
  std::string label_;
  long total_;
  bool enabled_;
  std::atomic<long> done_{0};
  std::mutex mutex_;
  std::chrono::steady_clock::time_point last_draw_;
};

}  // namespace omnical::cli

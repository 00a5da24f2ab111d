// Progress on a terminal for long work: a single updating line on stderr, only when
// stderr is a terminal and --quiet was not given. Thread-safe.
#pragma once

#include <atomic>
#include <chrono>
#include <mutex>
#include <string>

namespace omnical::cli {

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

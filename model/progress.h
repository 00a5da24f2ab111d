// Progress and cancellation for long library calls. The library never prints: a job's
// options carry an optional ProgressCallback; the caller draws bars (the CLI), forwards
// to Python, or returns false to stop the job, which then throws Cancelled (Ceres'
// IterationCallback and COLMAP's controller callbacks work the same way).
#pragma once

#include <atomic>
#include <exception>
#include <functional>
#include <mutex>
#include <stdexcept>
#include <string>
#include <utility>

#include "model/forced_unwind.h"

namespace omnical {

struct ProgressUpdate {
  std::string stage;  // e.g. "detect", "fit", "remap table"
  long done = 0;
  long total = 0;     // 0: unknown
};

// Returns false to cancel the job. Called from one thread at a time, possibly not the
// caller's.
using ProgressCallback = std::function<bool(const ProgressUpdate&)>;

// Thrown by a job whose callback returned false. Outputs written atomically are left as
// they were.
class Cancelled : public std::runtime_error {
 public:
  explicit Cancelled(const std::string& stage) : std::runtime_error("cancelled during " + stage) {}
};

// One stage of a job: counts work from any thread, calls the callback serialised, and
// remembers a cancellation. Worker threads call Advance and stop when it returns false;
// the thread that started them calls ThrowIfCancelled after joining them.
class ProgressReporter {
 public:
  ProgressReporter(ProgressCallback callback, std::string stage, long total)
      : callback_(std::move(callback)), stage_(std::move(stage)), total_(total) {
    Report();
  }
  // False once the caller asked to stop.
  bool Advance(long amount = 1) {
    done_ += amount;
    return Report();
  }
  bool cancelled() const { return cancelled_; }
  // Rethrows what the callback threw (it may run on a worker thread, where an exception
  // would end the process), else Cancelled.
  void ThrowIfCancelled() const {
    if (!cancelled_) return;
    if (thrown_) std::rethrow_exception(thrown_);
    throw Cancelled(stage_);
  }
  // Advance, then throw if cancelled: for single-threaded loops.
  void Step(long amount = 1) {
    Advance(amount);
    ThrowIfCancelled();
  }

 private:
  bool Report() {
    if (cancelled_) return false;
    if (!callback_) return true;
    std::lock_guard<std::mutex> lock(mutex_);
    try {
      // The count read under the lock: reports from several threads never go backwards,
      // and the last one has the total.
      if (!callback_({stage_, done_.load(), total_})) cancelled_ = true;
    } OMNICAL_RETHROW_FORCED_UNWIND catch (...) {
      if (!thrown_) thrown_ = std::current_exception();
      cancelled_ = true;
    }
    return !cancelled_;
  }
  ProgressCallback callback_;
  std::string stage_;
  long total_;
  std::atomic<long> done_{0};
  std::atomic<bool> cancelled_{false};
  std::exception_ptr thrown_;  // guarded by mutex_; read once the workers are joined
  std::mutex mutex_;
};

}  // namespace omnical

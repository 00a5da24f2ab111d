// The first exception any of several threads threw, kept for the thread that joins them
// to rethrow (thrown on a worker thread it would end the process).
#pragma once

#include <exception>
#include <mutex>
#include <utility>

namespace omnical {

class FirstError {
 public:
  // Keeps `error` unless an earlier one is kept.
  void Keep(std::exception_ptr error) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!error_) error_ = std::move(error);
  }
  // Rethrows the kept exception, if any.
  void RethrowIfAny() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (error_) std::rethrow_exception(error_);
  }

 private:
  std::mutex mutex_;
  std::exception_ptr error_;
};

}  // namespace omnical

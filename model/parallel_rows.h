// Rows of an image-sized job handed out one at a time to a few threads (the calling thread
// is one of them): rows cost different amounts (some see no mirror), so a shared counter
// balances them better than fixed blocks.
#pragma once

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "model/worker_threads.h"

namespace omnical {

// Calls row(v) once for every v in [0, rows), from `threads` threads (at least one). A
// row that throws stops the rows not yet started; the first exception is rethrown here
// once every thread has finished (thrown on a worker thread it would end the process).
template <typename RowFunction>
void ParallelRows(int rows, int threads, const RowFunction& row) {
  std::atomic<int> next{0};
  std::exception_ptr thrown;
  std::mutex thrown_mutex;
  auto work = [&]() {
    for (int v = next++; v < rows; v = next++) {
      try {
        row(v);
      } catch (...) {
        std::lock_guard<std::mutex> lock(thrown_mutex);
        if (!thrown) thrown = std::current_exception();
        next = rows;
      }
    }
  };
  std::vector<std::thread> pool;
  StartWorkers(std::min(threads, rows), work, &pool);
  work();
  for (std::thread& thread : pool) thread.join();
  if (thrown) std::rethrow_exception(thrown);
}

}  // namespace omnical

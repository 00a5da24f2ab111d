// Rows of an image-sized job handed out one at a time to a few threads (the calling thread
// is one of them): rows cost different amounts (some see no mirror), so a shared counter
// balances them better than fixed blocks.
#pragma once

#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

#include "model/first_error.h"
#include "model/forced_unwind.h"
#include "model/worker_threads.h"

namespace omnical {

// Calls row(v) once for every v in [0, rows), from `threads` threads (at least one). A
// row that throws stops the rows not yet started; the first exception is rethrown here
// once every thread has finished (thrown on a worker thread it would end the process).
template <typename RowFunction>
void ParallelRows(int rows, int threads, const RowFunction& row) {
  std::atomic<int> next{0};
  FirstError thrown;
  auto work = [&]() {
    for (int v = next++; v < rows; v = next++) {
      try {
        row(v);
      } OMNICAL_RETHROW_FORCED_UNWIND catch (...) {
        thrown.Keep(std::current_exception());
        next = rows;
      }
    }
  };
  std::vector<std::thread> pool;
  StartWorkers(std::min(threads, rows), work, &pool);
  work();
  for (std::thread& thread : pool) thread.join();
  thrown.RethrowIfAny();
}

}  // namespace omnical

// Worker threads for a job's parallel loop: the caller's thread plus up to count - 1 more.
#pragma once

#include <algorithm>
#include <system_error>
#include <thread>
#include <vector>

namespace omnical {

// More threads than this only cost memory: a caller's huge count is cut.
constexpr int kMaxWorkerThreads = 256;

// Starts up to count - 1 threads running work (the caller is the first); stops at the
// system's limit instead of failing (a thread that cannot start is not needed: the
// others share its work).
template <typename Work>
void StartWorkers(int count, const Work& work, std::vector<std::thread>* pool) {
  for (int t = 1; t < std::min(count, kMaxWorkerThreads); ++t) {
    try {
      pool->emplace_back(work);
    } catch (const std::system_error&) {
      break;
    }
  }
}

}  // namespace omnical

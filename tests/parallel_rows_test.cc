// The row loop every image-sized job shares (model/parallel_rows.h): each row once, and a
// row's exception reaches the caller instead of ending the process from a worker thread.
#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <vector>

#include "model/parallel_rows.h"

namespace omnical {
namespace {

TEST(ParallelRows, CallsEveryRowOnce) {
  for (int threads : {1, 2, 5}) {
    std::vector<std::atomic<int>> calls(257);
    ParallelRows(257, threads, [&](int v) { ++calls[v]; });
    for (int v = 0; v < 257; ++v) EXPECT_EQ(calls[v].load(), 1) << "row " << v << ", " << threads << " threads";
  }
}

TEST(ParallelRows, RethrowsARowsExceptionInTheCaller) {
  for (int threads : {1, 2, 4}) {
    std::atomic<int> started{0};
    try {
      ParallelRows(1000, threads, [&](int v) {
        ++started;
        if (v == 37) throw std::runtime_error("row 37 failed");
      });
      ADD_FAILURE() << "no exception with " << threads << " threads";
    } catch (const std::runtime_error& e) {
      EXPECT_STREQ(e.what(), "row 37 failed");
    }
    // The rows after it are not started (with more threads, others may be mid-row).
    if (threads == 1) {
      EXPECT_EQ(started.load(), 38);
    }
  }
}

}  // namespace
}  // namespace omnical

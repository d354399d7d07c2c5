#include <gtest/gtest.h>

#include <atomic>
#include <numeric>
#include <stdexcept>
#include <vector>

#include "nsg/core/parallel.h"

namespace nsg {

TEST(Parallel, EveryIndexRunsOnceAtAnyThreadCount) {
  for (int threads : {1, 2, 4}) {
    std::vector<std::atomic<int>> hits(1000);
    parallel_for(hits.size(), threads, [&](size_t i) { ++hits[i]; });
    for (auto& h : hits) ASSERT_EQ(h.load(), 1);
  }
}

TEST(Parallel, PoolIsReusable) {
  ThreadPool pool(3);
  for (int round = 0; round < 50; ++round) {
    std::vector<int> out(97, 0);
    pool.parallel_for(out.size(), [&](size_t i) { out[i] = static_cast<int>(i) * 2; });
    for (size_t i = 0; i < out.size(); ++i) ASSERT_EQ(out[i], static_cast<int>(i) * 2);
  }
}

TEST(Parallel, LowestIndexExceptionIsRethrown) {
  ThreadPool pool(2);
  try {
    pool.parallel_for(100, [](size_t i) {
      if (i == 5 || i == 50) throw std::runtime_error("fail at " + std::to_string(i));
    });
    FAIL();
  } catch (const std::runtime_error& e) {
    // With 2 threads index 50 may fail too, but index 5 always wins.
    EXPECT_STREQ(e.what(), "fail at 5");
  }
}

}  // namespace nsg

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <numeric>
#include <stdexcept>
#include <thread>
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

// Per-lane accumulators: every index once, lanes in [0, lane_count), never two indices of
// one lane at the same time (a lane's accumulator needs no lock), sums reduce to the total.
TEST(Parallel, LanesRunEveryIndexOnceOneAtATimePerLane) {
  for (int threads : {1, 2, 4}) {
    const size_t n = 500;
    EXPECT_EQ(lane_count(n, threads), static_cast<size_t>(threads));
    EXPECT_EQ(lane_count(2, threads), std::min<size_t>(2, static_cast<size_t>(threads)));
    std::vector<std::atomic<int>> hits(n);
    std::vector<std::atomic<int>> busy(lane_count(n, threads));
    std::vector<uint64_t> sums(lane_count(n, threads), 0);  // unsynchronised on purpose
    std::atomic<bool> overlap{false}, bad_lane{false};
    parallel_for_lanes(n, threads, [&](size_t lane, size_t i) {
      if (lane >= busy.size()) {
        bad_lane = true;
        return;
      }
      if (busy[lane].fetch_add(1) != 0) overlap = true;
      ++hits[i];
      sums[lane] += i;
      std::this_thread::yield();  // give the other lanes a chance to overlap
      --busy[lane];
    });
    EXPECT_FALSE(bad_lane);
    EXPECT_FALSE(overlap);
    for (auto& h : hits) ASSERT_EQ(h.load(), 1);
    EXPECT_EQ(std::accumulate(sums.begin(), sums.end(), uint64_t{0}), uint64_t{n * (n - 1) / 2});
  }
  parallel_for_lanes(0, 2, [](size_t, size_t) { FAIL(); });
}

TEST(Parallel, LanesRethrowTheLowestFailingIndex) {
  for (int round = 0; round < 20; ++round) {
    try {
      parallel_for_lanes(100, 2, [](size_t, size_t i) {
        if (i == 7 || i == 8 || i == 60) throw std::runtime_error("fail at " + std::to_string(i));
      });
      FAIL();
    } catch (const std::runtime_error& e) {
      EXPECT_STREQ(e.what(), "fail at 7");
    }
  }
}

}  // namespace nsg

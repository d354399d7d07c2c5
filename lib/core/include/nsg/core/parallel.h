#pragma once
// A fixed thread pool and a parallel-for over it. Work is handed out by index; callers
// write results into per-index slots and reduce in index order, so outputs never depend
// on the thread count. The first exception (by lowest index) is rethrown to the caller.
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace nsg {

// 0 -> std::thread::hardware_concurrency() (at least 1).
int resolve_threads(int threads);

class ThreadPool {
 public:
  explicit ThreadPool(int threads);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  int size() const { return static_cast<int>(workers_.size()) + 1; }
  // Runs fn(i) for i in [0, n) on the pool and the calling thread; blocks until done.
  void parallel_for(size_t n, const std::function<void(size_t)>& fn);

 private:
  struct Job;
  void worker_loop();

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable done_;
  Job* job_ = nullptr;
  uint64_t generation_ = 0;
  bool stop_ = false;
};

// One-shot helper: a temporary pool of `threads` (0 = all cores).
void parallel_for(size_t n, int threads, const std::function<void(size_t)>& fn);

// For reductions into per-lane accumulators: runs fn(lane, i) for i in [0, n) on
// lane_count(n, threads) lanes; a lane runs one i at a time, so its accumulator needs no
// lock, and a lane takes the next i as it finishes one (balanced load). Which lane gets
// which i depends on timing: use it only where the result does not depend on grouping
// (an associative, commutative reduction of the lanes). Errors as parallel_for: no i is
// started after a failure, and the lowest failing i is rethrown.
size_t lane_count(size_t n, int threads);
void parallel_for_lanes(size_t n, int threads, const std::function<void(size_t lane, size_t i)>& fn);

}  // namespace nsg

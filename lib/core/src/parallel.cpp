#include "nsg/core/parallel.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <limits>

namespace nsg {

int resolve_threads(int threads) {
  if (threads > 0) return threads;
  const unsigned hw = std::thread::hardware_concurrency();
  return hw == 0 ? 1 : static_cast<int>(hw);
}

struct ThreadPool::Job {
  size_t n = 0;
  const std::function<void(size_t)>* fn = nullptr;
  std::atomic<size_t> next{0};
  std::atomic<int> active{0};
  std::mutex error_mutex;
  size_t error_index = std::numeric_limits<size_t>::max();
  std::exception_ptr error;

  void run() {
    for (size_t i; (i = next.fetch_add(1)) < n;) {
      try {
        (*fn)(i);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (i < error_index) {
          error_index = i;
          error = std::current_exception();
        }
        next = n;  // stop handing out work
      }
    }
  }
};

ThreadPool::ThreadPool(int threads) {
  const int n = resolve_threads(threads);
  for (int i = 1; i < n; ++i) workers_.emplace_back([this] { worker_loop(); });
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  for (std::thread& t : workers_) t.join();
}

void ThreadPool::worker_loop() {
  uint64_t seen = 0;
  for (;;) {
    Job* job = nullptr;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || (job_ != nullptr && generation_ != seen); });
      if (stop_) return;
      seen = generation_;
      job = job_;
      ++job->active;
    }
    job->run();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      --job->active;
    }
    done_.notify_all();
  }
}

void ThreadPool::parallel_for(size_t n, const std::function<void(size_t)>& fn) {
  if (n == 0) return;
  Job job;
  job.n = n;
  job.fn = &fn;
  if (!workers_.empty() && n > 1) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      job_ = &job;
      ++generation_;
    }
    wake_.notify_all();
    job.run();
    std::unique_lock<std::mutex> lock(mutex_);
    job_ = nullptr;  // late workers will not pick it up any more
    done_.wait(lock, [&] { return job.active.load() == 0; });
  } else {
    job.run();
  }
  if (job.error) std::rethrow_exception(job.error);
}

void parallel_for(size_t n, int threads, const std::function<void(size_t)>& fn) {
  ThreadPool pool(threads);
  pool.parallel_for(n, fn);
}

size_t lane_count(size_t n, int threads) { return std::min(n, static_cast<size_t>(resolve_threads(threads))); }

void parallel_for_lanes(size_t n, int threads, const std::function<void(size_t lane, size_t i)>& fn) {
  std::atomic<size_t> next{0};
  std::mutex error_mutex;
  size_t error_index = std::numeric_limits<size_t>::max();
  std::exception_ptr error;
  parallel_for(lane_count(n, threads), threads, [&](size_t lane) {
    for (size_t i; (i = next.fetch_add(1)) < n;) {
      try {
        fn(lane, i);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (i < error_index) {
          error_index = i;
          error = std::current_exception();
        }
        next = n;  // stop handing out work; this lane's accumulator is abandoned
        return;
      }
    }
  });
  if (error) std::rethrow_exception(error);
}

}  // namespace nsg

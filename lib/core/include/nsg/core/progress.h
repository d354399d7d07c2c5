#pragma once
// Progress of long work: on a terminal one line redrawn in place (at most ~10 times a
// second); otherwise a plain log line every `plain_interval_s` seconds and at the end.
// Thread-safe: workers call advance() concurrently.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace nsg {

class Progress {
 public:
  // total = 0 means unknown. enabled = false silences it (e.g. --quiet).
  Progress(std::string label, uint64_t total, bool enabled = true);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void advance(uint64_t n = 1);
  // Extra text shown after the counters (e.g. "12.3 MB written").
  void set_detail(std::string detail);
  // Prints the final line (idempotent; also called by the destructor).
  void finish();

  uint64_t done() const { return done_.load(); }

 private:
  void maybe_draw(bool force);
  std::string render_line() const;

  std::string label_;
  std::string detail_;
  uint64_t total_;
  bool enabled_;
  bool tty_;
  bool finished_ = false;
  double plain_interval_s_ = 5.0;
  std::atomic<uint64_t> done_{0};
  std::mutex mutex_;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
};

}  // namespace nsg

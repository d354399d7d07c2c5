#include "nsg/core/progress.h"

#include <unistd.h>

#include <cstdio>

#include "nsg/core/log.h"

namespace nsg {

Progress::Progress(std::string label, uint64_t total, bool enabled)
    : label_(std::move(label)),
      total_(total),
      enabled_(enabled && log::level() <= log::Level::kInfo),
      tty_(isatty(STDERR_FILENO) == 1),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

Progress::~Progress() { finish(); }

void Progress::advance(uint64_t n) {
  done_ += n;
  maybe_draw(false);
}

void Progress::set_detail(std::string detail) {
  std::lock_guard<std::mutex> lock(mutex_);
  detail_ = std::move(detail);
}

std::string Progress::render_line() const {
  using namespace std::chrono;
  const double elapsed_s = duration<double>(steady_clock::now() - start_).count();
  const uint64_t done = done_.load();
  char buf[256];
  if (total_ > 0) {
    const double frac = static_cast<double>(done) / static_cast<double>(total_);
    const double eta_s = frac > 0 ? elapsed_s * (1.0 - frac) / frac : 0.0;
    std::snprintf(buf, sizeof buf, "%s: %llu/%llu (%.0f%%) %.1fs, ETA %.0fs", label_.c_str(),
                  static_cast<unsigned long long>(done), static_cast<unsigned long long>(total_), 100.0 * frac,
                  elapsed_s, eta_s);
  } else {
    std::snprintf(buf, sizeof buf, "%s: %llu %.1fs", label_.c_str(), static_cast<unsigned long long>(done), elapsed_s);
  }
  std::string line = buf;
  if (!detail_.empty()) line += ", " + detail_;
  return line;
}

void Progress::maybe_draw(bool force) {
  if (!enabled_) return;
  std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
  if (!force && !lock.owns_lock()) return;  // another thread is drawing
  if (force && !lock.owns_lock()) lock.lock();
  const auto now = std::chrono::steady_clock::now();
  const double since_s = std::chrono::duration<double>(now - last_draw_).count();
  if (!force && since_s < (tty_ ? 0.1 : plain_interval_s_)) return;
  last_draw_ = now;
  const std::string line = render_line();
  if (tty_) {
    std::fprintf(stderr, "\r\033[K%s%s", line.c_str(), force ? "\n" : "");
    std::fflush(stderr);
  } else {
    log::info(line);
  }
}

void Progress::finish() {
  if (finished_) return;
  finished_ = true;
  maybe_draw(true);
}

}  // namespace nsg

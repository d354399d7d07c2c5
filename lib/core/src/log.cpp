#include "nsg/core/log.h"

#include <atomic>
#include <cstdio>
#include <mutex>

namespace nsg::log {
namespace {
std::atomic<Level> g_level{Level::kInfo};
std::mutex g_mutex;

void emit(Level at, const char* tag, const std::string& message) {
  if (at < g_level.load()) return;
  std::lock_guard<std::mutex> lock(g_mutex);
  std::fprintf(stderr, "%s%s\n", tag, message.c_str());
  std::fflush(stderr);
}
}  // namespace

void set_level(Level level) { g_level = level; }
Level level() { return g_level.load(); }

void debug(const std::string& m) { emit(Level::kDebug, "debug: ", m); }
void info(const std::string& m) { emit(Level::kInfo, "", m); }
void warn(const std::string& m) { emit(Level::kWarn, "warning: ", m); }
void error(const std::string& m) { emit(Level::kError, "error: ", m); }

}  // namespace nsg::log

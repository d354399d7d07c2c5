#include "nsg/core/log.h"

#include <atomic>
#include <cstdio>
#include <mutex>
#include <string>

#include "nsg/core/strings.h"

namespace nsg::log {
namespace {
std::atomic<Level> g_level{Level::kInfo};
std::mutex g_mutex;

void emit(Level at, const char* tag, const std::string& message) {
  if (at < g_level.load()) return;
  std::lock_guard<std::mutex> lock(g_mutex);
  // One line per message as far as outside input goes: its CR, ESC or NUL are escaped
  // (a message's own line breaks stay).
  const std::string line = tag + printable_text(message, /*keep_newlines=*/true) + "\n";
  std::fwrite(line.data(), 1, line.size(), stderr);
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

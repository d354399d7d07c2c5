#pragma once
// Plain, thread-safe log lines on stderr. Commands set the level (--quiet, --verbose).
#include <string>

namespace nsg::log {

enum class Level { kDebug = 0, kInfo = 1, kWarn = 2, kError = 3, kSilent = 4 };

void set_level(Level level);
Level level();

void debug(const std::string& message);
void info(const std::string& message);
void warn(const std::string& message);
void error(const std::string& message);

}  // namespace nsg::log

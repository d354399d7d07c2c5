#include "nsg/core/memory.h"

#include <unistd.h>

#include <cctype>
#include <cmath>
#include <fstream>
#include <map>
#include <string>

#include "nsg/core/error.h"

namespace nsg {
namespace {

// The "<key>:   <n> kB" line of /proc/self/status, in bytes.
uint64_t status_kb(const std::string& key) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.compare(0, key.size(), key) != 0 || line.size() <= key.size() || line[key.size()] != ':') continue;
    return std::stoull(line.substr(key.size() + 1)) * 1024;
  }
  return 0;
}

}  // namespace

uint64_t current_rss_bytes() { return status_kb("VmRSS"); }
uint64_t peak_rss_bytes() { return status_kb("VmHWM"); }

uint64_t available_memory_bytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGE_SIZE);
  uint64_t bytes = pages > 0 && page > 0 ? static_cast<uint64_t>(pages) * static_cast<uint64_t>(page) : 0;
  std::ifstream cgroup("/sys/fs/cgroup/memory.max");
  std::string limit;
  if (cgroup >> limit && !limit.empty() && limit != "max" &&
      limit.find_first_not_of("0123456789") == std::string::npos && limit.size() < 20) {
    const uint64_t cap = std::stoull(limit);
    if (cap > 0 && (bytes == 0 || cap < bytes)) bytes = cap;
  }
  return bytes;
}

uint64_t parse_memory_size(const std::string& text, const std::string& what) {
  static const std::map<std::string, double> kUnits = {{"", 1.0},
                                                       {"B", 1.0},
                                                       {"K", 1e3},
                                                       {"KB", 1e3},
                                                       {"M", 1e6},
                                                       {"MB", 1e6},
                                                       {"G", 1e9},
                                                       {"GB", 1e9},
                                                       {"T", 1e12},
                                                       {"TB", 1e12},
                                                       {"KiB", 1024.0},
                                                       {"MiB", 1048576.0},
                                                       {"GiB", 1073741824.0},
                                                       {"TiB", 1099511627776.0}};
  const std::string expected = "a memory size such as 800M, 16G or 1.5GiB";
  size_t end = 0;
  double value = 0.0;
  try {
    value = std::stod(text, &end);
  } catch (const std::exception&) {
    throw ConfigError("", what, expected + " (got \"" + text + "\")");
  }
  std::string unit = text.substr(end);
  while (!unit.empty() && std::isspace(static_cast<unsigned char>(unit.front()))) unit.erase(unit.begin());
  const auto it = kUnits.find(unit);
  if (it == kUnits.end() || !std::isfinite(value) || !(value > 0.0) || value * it->second > 1.8e19)
    throw ConfigError("", what, expected + " (got \"" + text + "\")");
  return static_cast<uint64_t>(std::llround(value * it->second));
}

}  // namespace nsg

#include "nsg/core/files.h"

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "nsg/core/error.h"

namespace nsg {

std::string read_file(const std::filesystem::path& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) throw IoError(path.string(), "", std::string("cannot open: ") + std::strerror(errno));
  std::string out;
  char buf[1 << 16];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) out.append(buf, n);
  const bool failed = std::ferror(f) != 0;
  std::fclose(f);
  if (failed) throw IoError(path.string(), "", "read error");
  return out;
}

void require_file(const std::filesystem::path& path, const std::string& what) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw IoError(path.string(), "", "missing " + what + " (expected a readable file)");
  }
}

bool stays_inside(const std::string& relative) {
  const std::filesystem::path rel(relative);
  if (relative.empty() || !rel.is_relative() || rel.has_root_name()) return false;
  for (const std::filesystem::path& part : rel)
    if (part == "..") return false;
  return true;
}

}  // namespace nsg

#include "nsg/core/files.h"
#include "nsg/core/bounded_file.h"

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

std::string read_file_within(const std::filesystem::path& path, int64_t max_bytes, const std::string& what) {
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) throw IoError(path.string(), "", "cannot open: no such file (" + what + ")");
  // A device or FIFO has no size to check and could be read forever.
  if (!std::filesystem::is_regular_file(status)) throw ParseError(path.string(), "", what + " as a regular file");
  const auto too_big = [&](uintmax_t bytes) {
    return ParseError(path.string(), "",
                      what + " of at most " + std::to_string(max_bytes) + " bytes, got " + std::to_string(bytes));
  };
  const uintmax_t bytes = std::filesystem::file_size(path, ec);
  if (!ec && bytes > static_cast<uintmax_t>(max_bytes)) throw too_big(bytes);
  std::string text = read_file(path);
  if (static_cast<int64_t>(text.size()) > max_bytes) throw too_big(text.size());
  return text;
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

namespace {
// Absolute, normal, and without a trailing separator ("a/b/" names the folder b too).
std::filesystem::path absolute_folder(const std::filesystem::path& p) {
  std::filesystem::path a = std::filesystem::absolute(p).lexically_normal();
  if (a.filename().empty() && a.has_parent_path() && a != a.root_path()) a = a.parent_path();
  return a;
}
}  // namespace

std::string path_relative_to(const std::filesystem::path& target, const std::filesystem::path& document_dir) {
  if (target.empty()) return "";
  const std::filesystem::path to = absolute_folder(target);
  const std::filesystem::path rel = to.lexically_relative(absolute_folder(document_dir));
  return (rel.empty() ? to : rel).generic_string();
}

std::filesystem::path resolve_document_path(const std::string& stored, const std::filesystem::path& document_dir) {
  const std::filesystem::path path(stored);
  if (stored.empty() || path.is_absolute()) return path;
  const std::filesystem::path beside = (document_dir / path).lexically_normal();
  std::error_code ec;
  if (!std::filesystem::is_directory(beside, ec) && std::filesystem::is_directory(path, ec)) return path;
  return beside;
}

}  // namespace nsg

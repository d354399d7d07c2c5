#include "nsg/core/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <system_error>

#include "nsg/core/error.h"

namespace fs = std::filesystem;

namespace nsg {
namespace {
std::atomic<uint64_t> g_temp_counter{0};

std::string errno_text() { return std::strerror(errno); }

void fsync_path(const fs::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}
}  // namespace

fs::path temp_path_for(const fs::path& target) {
  return fs::path(target.string() + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(g_temp_counter++));
}

AtomicFileWriter::AtomicFileWriter(fs::path target, Durability durability)
    : target_(std::move(target)), durability_(durability) {
  std::error_code ec;
  if (target_.has_parent_path()) fs::create_directories(target_.parent_path(), ec);
  if (ec) throw IoError(target_.parent_path().string(), "", "cannot create folder: " + ec.message());
  temp_ = temp_path_for(target_);
  file_ = std::fopen(temp_.c_str(), "wb");
  if (file_ == nullptr) throw IoError(temp_.string(), "", "cannot create file: " + errno_text());
}

AtomicFileWriter::~AtomicFileWriter() {
  if (!committed_) abandon();
}

void AtomicFileWriter::abandon() noexcept {
  if (file_ != nullptr) std::fclose(file_);
  file_ = nullptr;
  std::error_code ec;
  fs::remove(temp_, ec);
}

void AtomicFileWriter::write(const void* data, size_t size) {
  if (file_ == nullptr) throw InternalError(target_.string(), "", "write after commit");
  if (size > 0 && std::fwrite(data, 1, size, file_) != size) {
    const std::string why = errno_text();
    abandon();
    throw IoError(target_.string(), "", "write failed: " + why);
  }
}

void AtomicFileWriter::commit() {
  if (file_ == nullptr) throw InternalError(target_.string(), "", "commit twice");
  const bool flushed =
      std::fflush(file_) == 0 && (durability_ == Durability::kDeferred || ::fsync(::fileno(file_)) == 0);
  const std::string why = errno_text();
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  if (!flushed || !closed) {
    abandon();
    throw IoError(target_.string(), "", "cannot finish writing: " + why);
  }
  if (::rename(temp_.c_str(), target_.c_str()) != 0) {
    const std::string rename_why = errno_text();
    abandon();
    throw IoError(target_.string(), "", "cannot rename temp file into place: " + rename_why);
  }
  committed_ = true;
  if (durability_ == Durability::kAtCommit && target_.has_parent_path()) fsync_path(target_.parent_path());
}

void write_file_atomic(const fs::path& target, std::string_view data, Durability durability) {
  AtomicFileWriter w(target, durability);
  w.write(data);
  w.commit();
}

void flush_file_system(const fs::path& folder) {
  const int fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY);
  const bool ok = fd >= 0 && ::syncfs(fd) == 0;
  const std::string why = errno_text();
  if (fd >= 0) ::close(fd);
  if (!ok) throw IoError(folder.string(), "", "cannot flush the written files to disk: " + why);
}

void commit_rename(const fs::path& from, const fs::path& to) {
  fsync_path(from);
  if (::rename(from.c_str(), to.c_str()) != 0) {
    throw IoError(to.string(), "", "cannot rename " + from.string() + " into place: " + errno_text());
  }
  if (to.has_parent_path()) fsync_path(to.parent_path());
}

}  // namespace nsg

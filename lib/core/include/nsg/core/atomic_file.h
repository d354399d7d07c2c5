#pragma once
// Outputs appear whole or not at all: data goes to a temp file in the target's folder,
// is flushed to disk, then renamed over the target. A writer destroyed before commit()
// removes its temp file, so an error or exception leaves nothing half-written behind.
#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>

namespace nsg {

// When a committed file reaches the disk: at commit (the file and its folder fsynced), or
// deferred to one flush_file_system() before the document that declares the files whole
// (a manifest) is written — thousands of small records otherwise cost two fsyncs each.
enum class Durability { kAtCommit, kDeferred };

class AtomicFileWriter {
 public:
  // Creates the parent folder if needed; throws IoError naming the path on failure.
  explicit AtomicFileWriter(std::filesystem::path target, Durability durability = Durability::kAtCommit);
  ~AtomicFileWriter();
  AtomicFileWriter(const AtomicFileWriter&) = delete;
  AtomicFileWriter& operator=(const AtomicFileWriter&) = delete;

  void write(const void* data, size_t size);
  void write(std::string_view data) { write(data.data(), data.size()); }
  // The open temp file, for libraries that want a FILE* (libpng, …).
  std::FILE* file() { return file_; }
  const std::filesystem::path& temp_path() const { return temp_; }
  const std::filesystem::path& target() const { return target_; }
  // Flush, fsync (unless deferred), close, rename. Throws IoError (e.g. disk full) and
  // removes the temp.
  void commit();

 private:
  void abandon() noexcept;
  std::filesystem::path target_;
  std::filesystem::path temp_;
  std::FILE* file_ = nullptr;
  bool committed_ = false;
  Durability durability_ = Durability::kAtCommit;
};

// Temp name used for `target` by this process: "<target>.tmp-<pid>-<n>".
std::filesystem::path temp_path_for(const std::filesystem::path& target);
// Writes `data` to `target` atomically.
void write_file_atomic(const std::filesystem::path& target, std::string_view data,
                       Durability durability = Durability::kAtCommit);
// Every write to the file system holding `folder` reaches the disk (syncfs): what makes
// Durability::kDeferred files durable. IoError naming the folder when it fails.
void flush_file_system(const std::filesystem::path& folder);
// Renames `from` over `to` after fsync of `from`; throws IoError.
void commit_rename(const std::filesystem::path& from, const std::filesystem::path& to);

}  // namespace nsg

#pragma once
// WebDataset shards: POSIX tar (ustar, pax headers only for long names) written and read
// through libarchive, whose types stay out of this header.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace nsg::io {

// Writes members in call order with reproducible headers (mtime 0, uid/gid 0, empty
// uname/gname, mode 0644, regular files). Bytes go to a temp file next to the target
// ("<path>.tmp-<pid>-<n>", see AtomicFileWriter) that finish() renames into place; a
// writer destroyed without finish() removes the temp file.
class TarWriter {
 public:
  explicit TarWriter(std::filesystem::path final_path);
  ~TarWriter();
  TarWriter(const TarWriter&) = delete;
  TarWriter& operator=(const TarWriter&) = delete;

  // Throws ConfigError for an empty, absolute, "..", or repeated member name; IoError on
  // write failures.
  void add(const std::string& member_name, std::span<const uint8_t> bytes);

  struct Result {
    std::string sha256_hex;  // of the final file's bytes
    uint64_t bytes = 0;      // final file size
    size_t members = 0;
  };
  Result finish();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

struct TarMember {
  std::string name;
  std::vector<uint8_t> bytes;
};

// Streams the regular-file members of a tar in order (directories and other entries are
// skipped). Throws IoError if the file cannot be opened, ParseError naming the file and
// member on a corrupt or truncated archive (including a missing end-of-archive marker).
class TarReader {
 public:
  explicit TarReader(const std::filesystem::path& path);
  ~TarReader();
  TarReader(const TarReader&) = delete;
  TarReader& operator=(const TarReader&) = delete;

  // Fills `out` with the next member; false at the end of the archive.
  bool next(TarMember& out);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace nsg::io

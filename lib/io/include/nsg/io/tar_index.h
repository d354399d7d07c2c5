#pragma once
// Random access into WebDataset tar shards without unpacking them: one pass over the
// 512-byte headers gives every regular member's data offset and size; a member is then one
// positioned read (pread), so any tile of any shard can be read in any order, from any
// process (the Python Dataset's DataLoader workers).
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace nsg::io {

struct TarIndexEntry {
  std::string name;     // member name (pax "path" / GNU long name when present)
  uint64_t offset = 0;  // byte offset of the member's data in the file
  uint64_t size = 0;    // bytes of data
};

// The regular-file members of a ustar / pax / GNU tar, in archive order (what TarReader
// streams). Reads headers only. Throws IoError if the file cannot be read, ParseError
// naming the file and the header's offset or member on a bad checksum, a size that is
// not octal, a member running past the end of the file, or a missing end-of-archive
// marker (two zero blocks) — the same archives TarReader refuses.
std::vector<TarIndexEntry> index_tar(const std::filesystem::path& path);

// A shard member is a regular file with a relative name free of '..' components, each name
// once; links and special files are refused (ParseError naming the file and the member).
// Shared by index_tar and TarReader so both refuse the same archives.
void check_tar_member_name(const std::string& file, const std::string& name);
// `type` is the ustar type flag ('0' regular, '5' folder, '1'/'2' links, ...).
void check_tar_member_type(const std::string& file, const std::string& name, char type);

// Reads [offset, offset + size) of an open file descriptor, looping over short reads.
// Throws IoError naming `file_label` and `record` on an error or a short file.
void read_at(int fd, uint64_t offset, void* out, size_t size, const std::string& file_label, const std::string& record);

}  // namespace nsg::io

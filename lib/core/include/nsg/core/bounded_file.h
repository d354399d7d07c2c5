#pragma once
// Reading a document whose format bounds its size: the bound is checked before the bytes
// are read, so a link to a device or a huge file costs nothing.
#include <cstdint>
#include <filesystem>
#include <string>

namespace nsg {

// Reads a regular file of at most `max_bytes`, checked before it is read and again after
// (it may grow between): a link to a device or FIFO, or a larger file, is a ParseError naming
// it and `what` ("a done-record"); missing or unreadable an IoError.
std::string read_file_within(const std::filesystem::path& path, int64_t max_bytes, const std::string& what);

}  // namespace nsg

#pragma once
// gzip for model files (zlib): deterministic bytes (no name, mtime 0).
#include <filesystem>
#include <string>

namespace nsg::model {

std::string gzip_compress(const std::string& data);
// The file's bytes, gunzipped when they start with the gzip magic. IoError / ParseError
// naming the file.
std::string read_maybe_gzip(const std::filesystem::path& path);

}  // namespace nsg::model

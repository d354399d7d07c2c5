#pragma once
// gzip for model files (zlib): deterministic bytes (no name, mtime 0).
#include <cstdint>
#include <filesystem>
#include <string>

namespace nsg::model {

// The largest model text read, on disk or inflated: forests of hundreds of deep trees take
// tens of MiB of YAML; a gzip bomb is stopped here, before memory runs out.
inline constexpr uint64_t kMaxModelTextBytes = uint64_t{256} << 20;

std::string gzip_compress(const std::string& data);
// The file's bytes, gunzipped when they start with the gzip magic. IoError / ParseError
// naming the file.
std::string read_maybe_gzip(const std::filesystem::path& path, uint64_t max_text_bytes = kMaxModelTextBytes);

}  // namespace nsg::model

#pragma once
// SHA-256 (OpenSSL EVP behind the interface) for shard and input hashes.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>

namespace nsg {

class Sha256 {
 public:
  Sha256();
  ~Sha256();
  Sha256(const Sha256&) = delete;
  Sha256& operator=(const Sha256&) = delete;

  void update(const void* data, size_t size);
  void update(std::string_view data) { update(data.data(), data.size()); }
  // Lowercase hex digest; the object cannot be updated afterwards.
  std::string hex_digest();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

std::string sha256_hex(std::string_view data);
// Streams the file; throws IoError naming it when unreadable.
std::string sha256_file(const std::filesystem::path& path);

}  // namespace nsg

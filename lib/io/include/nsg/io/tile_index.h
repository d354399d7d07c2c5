#pragma once
// Random access to the tiles of one split of a dataset (tar or folder layout), for the
// Python Dataset: the tile keys in manifest order and, per tile, where each member's
// bytes are. Tar shards are indexed once per process (index_tar, cached by path, size and
// modification time) and read with positioned reads: no unpacking, no shared file offset,
// so forked DataLoader workers can read concurrently.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "nsg/io/dataset.h"

namespace nsg::io {

class SplitIndex {
 public:
  // Reads <root>/manifest.json (Dataset::open: IoError / ParseError naming it) and indexes every shard of
  // `split` — a split or a ladder rung of one ("test-r1", Dataset::shards). ConfigError
  // naming the manifest and the names it has (Dataset::split_names) when `split` has no
  // shard; DataError naming the shard when its tile count differs from the manifest's.
  SplitIndex(const std::filesystem::path& root, const std::string& split);

  size_t size() const { return tiles_.size(); }
  const std::string& key(size_t i) const { return tiles_.at(i).key; }
  const std::string& shard_name(size_t i) const { return shards_.at(tiles_.at(i).shard).name; }
  const std::filesystem::path& root() const { return root_; }
  const std::string& split() const { return split_; }
  bool tar_layout() const { return tar_; }
  // The manifest's tile_format.size_px: rasters must have this size.
  int size_px() const { return size_px_; }
  // Suffixes ("lidar.tif", "graph.json", …) the tile has, in archive / name order.
  std::vector<std::string> suffixes(size_t i) const;

  // The tile's members with the given suffixes (every member when empty). ParseError
  // naming "<key>.<suffix>" and the shard when one is missing; IoError on read failures.
  // Thread-safe: each call opens its own file descriptor.
  DatasetTile read(size_t i, const std::vector<std::string>& suffixes = {}) const;

 private:
  struct Member {
    std::string suffix;
    uint64_t offset = 0;  // in the shard (tar); 0 for a folder file
    uint64_t size = 0;
  };
  struct Tile {
    std::string key;
    uint32_t shard = 0;
    std::vector<Member> members;
  };
  struct Shard {
    std::string name;
    std::filesystem::path path;  // the tar file, or the split's tile folder
  };

  void index_tar_shard(const ShardEntry& entry);
  void index_folder_shard(const ShardEntry& entry);

  std::filesystem::path root_;
  std::string split_;
  bool tar_ = true;
  int size_px_ = 256;
  std::vector<Shard> shards_;
  std::vector<Tile> tiles_;
};

}  // namespace nsg::io

#include "nsg/io/tile_index.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <tuple>

#include "nsg/core/error.h"
#include "nsg/core/strings.h"
#include "nsg/io/tar_index.h"

namespace fs = std::filesystem;

namespace nsg::io {
namespace {

using Entries = std::vector<TarIndexEntry>;

// Per process: a shard is indexed once, however many SplitIndex objects read it. The key
// includes size and mtime so a regenerated shard is indexed again.
std::shared_ptr<const Entries> cached_tar_index(const fs::path& file) {
  static std::mutex mutex;
  static std::map<std::tuple<std::string, uint64_t, int64_t>, std::shared_ptr<const Entries>> cache;
  std::error_code ec;
  const fs::path abs = fs::absolute(file, ec);
  const uint64_t size = fs::file_size(file, ec);
  NSG_CHECK(!ec, IoError, file.string(), "", "a readable shard: " + ec.message());
  const int64_t mtime = fs::last_write_time(file, ec).time_since_epoch().count();
  const auto key = std::make_tuple(abs.string(), size, mtime);
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (auto it = cache.find(key); it != cache.end()) return it->second;
  }
  auto entries = std::make_shared<const Entries>(index_tar(file));  // outside the lock
  std::lock_guard<std::mutex> lock(mutex);
  return cache.emplace(key, std::move(entries)).first->second;
}

// "<dir>/<key>.<suffix>" with a dot-free key.
std::pair<std::string, std::string> split_member(const std::string& name, const std::string& where) {
  const std::string base = name.substr(name.find_last_of('/') + 1);
  const size_t dot = base.find('.');
  NSG_CHECK(dot != std::string::npos && dot != 0, ParseError, where, name, "a member named <key>.<suffix>");
  return {base.substr(0, dot), base.substr(dot + 1)};
}

struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

int open_read(const fs::path& path, const std::string& record) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  NSG_CHECK(fd >= 0, IoError, path.string(), record, std::string("a readable file: ") + std::strerror(errno));
  return fd;
}

}  // namespace

SplitIndex::SplitIndex(const fs::path& root, const std::string& split) : root_(root), split_(split) {
  const Dataset ds = Dataset::open(root);
  tar_ = ds.tar_layout();
  size_px_ = ds.manifest().tile_format.size_px;  // bounded by the manifest's reader
  const std::vector<ShardEntry> entries = ds.shards(split);
  if (entries.empty()) {
    const std::vector<std::string> names = ds.split_names();
    throw ConfigError(ds.manifest_file(), "split '" + split + "'",
                      "a split with shards; the dataset has: " + (names.empty() ? "none" : join(names, ", ")));
  }
  for (const ShardEntry& entry : entries) {
    const size_t before = tiles_.size();
    tar_ ? index_tar_shard(entry) : index_folder_shard(entry);
    const int64_t expected = entry.tiles;
    NSG_CHECK(
        static_cast<int64_t>(tiles_.size() - before) == expected, DataError, shards_.back().path.string(),
        "shard '" + shards_.back().name + "'",
        std::to_string(expected) + " tiles as the manifest says, found " + std::to_string(tiles_.size() - before));
  }
}

void SplitIndex::index_tar_shard(const ShardEntry& entry) {
  const auto shard = static_cast<uint32_t>(shards_.size());
  const std::string& name = entry.name;
  shards_.push_back({name, path_in_dataset(root_, entry.file, "shard '" + name + "' file")});
  const fs::path& file = shards_.back().path;
  for (const TarIndexEntry& e : *cached_tar_index(file)) {
    auto [key, suffix] = split_member(e.name, file.string());
    // Members of a tile are consecutive (WebDataset); a key seen again starts no new tile.
    if (tiles_.empty() || tiles_.back().shard != shard || tiles_.back().key != key) tiles_.push_back({key, shard, {}});
    tiles_.back().members.push_back({suffix, e.offset, e.size});
  }
}

void SplitIndex::index_folder_shard(const ShardEntry& entry) {
  // Folder layout: <folder>/<key>/<key>.<suffix>, keys from first_key to last_key.
  const auto shard = static_cast<uint32_t>(shards_.size());
  const std::string& name = entry.name;
  shards_.push_back({name, path_in_dataset(root_, entry.folder, "shard '" + name + "' folder")});
  const fs::path& folder = shards_.back().path;
  const std::string &first = entry.first_key, &last = entry.last_key;
  NSG_CHECK(fs::is_directory(folder), IoError, folder.string(), "shard '" + shards_.back().name + "'",
            "the split's tile folder");
  std::vector<fs::path> dirs;
  for (const auto& e : fs::directory_iterator(folder)) {
    const std::string key = e.path().filename().string();
    if (e.is_directory() && key >= first && key <= last) dirs.push_back(e.path());
  }
  std::sort(dirs.begin(), dirs.end());
  for (const fs::path& dir : dirs) {
    Tile tile{dir.filename().string(), shard, {}};
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(dir))
      if (e.is_regular_file() && e.path().string().find(".tmp-") == std::string::npos) files.push_back(e.path());
    std::sort(files.begin(), files.end());
    for (const fs::path& f : files) {
      auto [key, suffix] = split_member(f.filename().string(), f.string());
      tile.members.push_back({suffix, 0, static_cast<uint64_t>(fs::file_size(f))});
    }
    tiles_.push_back(std::move(tile));
  }
}

std::vector<std::string> SplitIndex::suffixes(size_t i) const {
  std::vector<std::string> out;
  for (const Member& m : tiles_.at(i).members) out.push_back(m.suffix);
  return out;
}

DatasetTile SplitIndex::read(size_t i, const std::vector<std::string>& suffixes) const {
  NSG_CHECK(i < tiles_.size(), ConfigError, (root_ / "manifest.json").string(), "tile " + std::to_string(i),
            "an index below the split's " + std::to_string(tiles_.size()) + " tiles");
  const Tile& t = tiles_[i];
  const Shard& shard = shards_[t.shard];
  DatasetTile out{t.key, shard.name, {}};
  std::vector<const Member*> wanted;
  for (const Member& m : t.members)
    if (suffixes.empty() || std::find(suffixes.begin(), suffixes.end(), m.suffix) != suffixes.end())
      wanted.push_back(&m);
  for (const std::string& s : suffixes) {
    const bool found = std::any_of(wanted.begin(), wanted.end(), [&](const Member* m) { return m->suffix == s; });
    NSG_CHECK(found, ParseError, t.key + "." + s, shard.path.string(), "the tile's " + s + " (missing)");
  }
  Fd tar;
  if (tar_) tar.fd = open_read(shard.path, t.key);
  for (const Member* m : wanted) {
    std::vector<uint8_t>& bytes = out.files[m->suffix];
    bytes.resize(m->size);
    if (tar_) {
      read_at(tar.fd, m->offset, bytes.data(), bytes.size(), shard.path.string(), t.key + "." + m->suffix);
      continue;
    }
    const fs::path file = shard.path / t.key / (t.key + "." + m->suffix);
    Fd f;
    f.fd = open_read(file, "");
    read_at(f.fd, 0, bytes.data(), bytes.size(), file.string(), "");
  }
  return out;
}

}  // namespace nsg::io

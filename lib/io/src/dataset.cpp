#include "nsg/io/dataset.h"

#include <algorithm>
#include <regex>
#include <set>

#include "nsg/core/error.h"
#include "nsg/core/files.h"
#include "nsg/core/json.h"
#include "nsg/io/tar.h"
#include "nsg/io/tile_graph.h"

namespace nsg::io {

namespace fs = std::filesystem;

Raster DatasetTile::raster(const std::string& suffix) const {
  auto it = files.find(suffix);
  if (it == files.end()) throw ParseError(key + "." + suffix, shard, "the tile's " + suffix + " (missing)");
  return decode_geotiff(it->second, key + "." + suffix);
}

nlohmann::json DatasetTile::json(const std::string& suffix) const {
  auto it = files.find(suffix);
  if (it == files.end()) throw ParseError(key + "." + suffix, shard, "the tile's " + suffix + " (missing)");
  const std::vector<uint8_t>& bytes = it->second;
  return parse_json_strict(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()),
                           key + "." + suffix);
}

TileMeta DatasetTile::meta() const { return tile_meta_from_json(json("meta.json"), key + ".meta.json"); }

graph::TileGraph DatasetTile::graph() const { return tile_graph_from_json(json("graph.json"), key + ".graph.json"); }
std::optional<graph::TileGraph> DatasetTile::prior_graph() const {
  return tile_prior_graph_from_json(json("graph.json"), key + ".graph.json");
}

fs::path path_in_dataset(const fs::path& root, const std::string& relative, const std::string& record) {
  const fs::path rel(relative);
  NSG_CHECK(stays_inside(relative), ParseError, (root / "manifest.json").string(), record,
            "a relative path inside the dataset folder, got '" + relative + "'");
  return root / rel;
}

Dataset Dataset::open(const fs::path& root) {
  Dataset d;
  d.root_ = root;
  d.manifest_ = read_manifest(root / "manifest.json");
  return d;
}

std::optional<std::pair<std::string, int>> rung_split(const std::string& split) {
  static const std::regex kRungSplit(R"((train|val|test)-r([1-9][0-9]{0,5}))");
  std::smatch m;
  if (!std::regex_match(split, m, kRungSplit)) return std::nullopt;
  return std::pair{m[1].str(), std::stoi(m[2].str())};
}

std::vector<ShardEntry> Dataset::shards(const std::string& split) const {
  if (const auto rung = rung_split(split)) return rung_shards(rung->first, rung->second);
  std::vector<ShardEntry> out;
  for (const ShardEntry& s : manifest_.shards)
    if (split.empty() || s.split == split) out.push_back(s);
  return out;
}

std::vector<std::string> Dataset::split_names() const {
  const std::vector<std::string> base = splits();
  std::vector<std::string> out = base;
  for (const std::string& split : base)
    for (int rung : rungs())
      if (!rung_shards(split, rung).empty()) out.push_back(split + "-r" + std::to_string(rung));
  return out;
}

std::vector<int> Dataset::rungs() const {
  std::set<int> out;
  for (const ShardEntry& s : rung_shards()) out.insert(s.rung);
  return {out.begin(), out.end()};
}

std::vector<ShardEntry> Dataset::rung_shards(const std::string& split, int rung) const {
  std::vector<ShardEntry> out;
  if (!manifest_.ladder) return out;
  for (const ShardEntry& s : manifest_.ladder->shards)
    if ((split.empty() || s.split == split) && (rung == 0 || s.rung == rung)) out.push_back(s);
  return out;
}

uint64_t tile_count(const std::vector<ShardEntry>& shards) {
  uint64_t n = 0;
  for (const ShardEntry& s : shards) n += static_cast<uint64_t>(s.tiles);
  return n;
}

namespace {

// "<key>.<suffix>" with a dot-free key.
std::pair<std::string, std::string> split_member(const std::string& name, const std::string& where) {
  const std::string base = name.substr(name.find_last_of('/') + 1);
  const size_t dot = base.find('.');
  if (dot == std::string::npos || dot == 0) throw ParseError(where, name, "a member named <key>.<suffix>");
  return {base.substr(0, dot), base.substr(dot + 1)};
}

}  // namespace

std::vector<DatasetTile> Dataset::read_shard(const ShardEntry& shard) const {
  std::vector<DatasetTile> tiles;
  const std::string& name = shard.name;
  const auto add = [&](const std::string& member, std::vector<uint8_t> bytes, const std::string& where) {
    auto [key, suffix] = split_member(member, where);
    if (tiles.empty() || tiles.back().key != key) tiles.push_back({key, name, {}});
    tiles.back().files[suffix] = std::move(bytes);
  };
  if (tar_layout()) {
    const fs::path file = path_in_dataset(root_, shard.file, "shard '" + name + "' file");
    TarReader reader(file);
    TarMember m;
    while (reader.next(m)) add(m.name, std::move(m.bytes), file.string());
    return tiles;
  }
  // Folder layout: tiles/<split>/<key>/<key>.<suffix>, keys from first_key to last_key.
  const fs::path folder = path_in_dataset(root_, shard.folder, "shard '" + name + "' folder");
  const std::string &first = shard.first_key, &last = shard.last_key;
  std::vector<fs::path> dirs;
  if (fs::is_directory(folder))
    for (const auto& e : fs::directory_iterator(folder)) {
      const std::string key = e.path().filename().string();
      if (e.is_directory() && key >= first && key <= last) dirs.push_back(e.path());
    }
  std::sort(dirs.begin(), dirs.end());
  for (const fs::path& dir : dirs) {
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(dir))
      if (e.is_regular_file() && e.path().string().find(".tmp-") == std::string::npos) files.push_back(e.path());
    std::sort(files.begin(), files.end());
    for (const fs::path& f : files) {
      const std::string text = read_file(f);
      add(f.filename().string(), std::vector<uint8_t>(text.begin(), text.end()), f.string());
    }
  }
  return tiles;
}

void Dataset::for_each_tile(const std::string& split, const std::function<bool(const DatasetTile&)>& fn) const {
  for (const ShardEntry& shard : shards(split))
    for (const DatasetTile& t : read_shard(shard))
      if (!fn(t)) return;
}

void Dataset::for_each_rung_tile(const std::string& split, int rung,
                                 const std::function<bool(const DatasetTile&)>& fn) const {
  for (const ShardEntry& shard : rung_shards(split, rung))
    for (const DatasetTile& t : read_shard(shard))
      if (!fn(t)) return;
}

}  // namespace nsg::io

#pragma once
// Reading a NuScenesGraph dataset (docs/dataset-format.md) for validate, preview, score, stats,
// the report, the model and Python: the manifest through its one reader (io/manifest.h), and
// the tiles of a split streamed shard by shard (tar or folder layout) as raw member bytes with
// typed readers of their documents (io/tile_meta.h, io/tile_graph.h) and layers (io/raster.h).
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nsg/graph/clip.h"
#include "nsg/io/manifest.h"
#include "nsg/io/raster.h"
#include "nsg/io/tile_meta.h"

namespace nsg::io {

struct DatasetTile {
  std::string key;
  std::string shard;                                  // manifest shard name, e.g. "test-000000"
  std::map<std::string, std::vector<uint8_t>> files;  // suffix ("lidar.tif", "meta.json", …) → bytes
  bool has(const std::string& suffix) const { return files.count(suffix) > 0; }
  // Decoders; ParseError naming "<key>.<suffix>" when missing or malformed.
  Raster raster(const std::string& suffix) const;
  nlohmann::json json(const std::string& suffix) const;
  // The tile's documents through their one reader each: ParseError / DataError naming
  // "<key>.meta.json" / "<key>.graph.json" and the JSON path.
  TileMeta meta() const;
  graph::TileGraph graph() const;
  // A map-update tile's prior graph (graph.json's "prior"); nullopt when it has none.
  std::optional<graph::TileGraph> prior_graph() const;
};

// <root>/<relative> for a path the manifest gives (a shard's file or folder). ParseError
// naming <root>/manifest.json and `record` when it is empty, absolute or has '..'
// components: a manifest may not point outside its dataset.
std::filesystem::path path_in_dataset(const std::filesystem::path& root, const std::string& relative,
                                      const std::string& record);

// What Dataset::verify_split established about a split before it is read.
struct SplitVerification {
  int64_t shards = 0;   // listed for the split, all present
  int64_t tiles = 0;    // the manifest's tile count of those shards
  bool hashed = false;  // every shard's bytes matched the manifest's sha256 and size
};

// The tiles the manifest's shard entries `shards` count: a progress total, read before any
// shard is.
uint64_t tile_count(const std::vector<ShardEntry>& shards);

// A ladder rung as a split name: "test-r1" = rung 1 of split test ({"test", 1}); nullopt
// for other names. Dataset::shards, require_split, verify_split and for_each_tile take it,
// so every command that reads a split reads a rung the same way (predict --split test-r1).
std::optional<std::pair<std::string, int>> rung_split(const std::string& split);

class Dataset {
 public:
  // Reads <root>/manifest.json through read_manifest (every field checked, the format's
  // limits applied); IoError / ParseError / DataError naming it and the JSON pointer.
  static Dataset open(const std::filesystem::path& root);

  const std::filesystem::path& root() const { return root_; }
  // <root>/manifest.json: what every error about the manifest names.
  std::string manifest_file() const { return (root_ / "manifest.json").string(); }
  const Manifest& manifest() const { return manifest_; }
  bool tar_layout() const { return manifest_.tar_layout(); }
  // Shard entries of the manifest for `split` ("" = all; "<split>-r<k>" = the ladder's rung
  // k of it), in manifest order.
  std::vector<ShardEntry> shards(const std::string& split = "") const;
  // Calls fn for every tile of `split` ("" = all) in manifest order, one shard in memory
  // at a time. Stops early when fn returns false.
  void for_each_tile(const std::string& split, const std::function<bool(const DatasetTile&)>& fn) const;
  // The tiles of `split` ("" = all) as the manifest's shard entries count them (for a
  // progress total).
  uint64_t tile_count(const std::string& split = "") const { return io::tile_count(shards(split)); }
  // The split names the manifest's shards carry, sorted.
  std::vector<std::string> splits() const;
  // The names a reader may ask for: splits(), then "<split>-r<k>" for each of the ladder's
  // built rungs of each split (rung_split), in that order.
  std::vector<std::string> split_names() const;
  // The observation ladder (manifest "ladder", generate --ladder): the built rungs (scene
  // counts, ascending; the "all" rung is the split's own tiles), empty without a ladder.
  std::vector<int> rungs() const;
  // The ladder's shard entries of `split` ("" = all) and `rung` (0 = every rung), in
  // manifest order.
  std::vector<ShardEntry> rung_shards(const std::string& split = "", int rung = 0) const;
  // for_each_tile over the rung shards of `split` and `rung`.
  void for_each_rung_tile(const std::string& split, int rung, const std::function<bool(const DatasetTile&)>& fn) const;
  // DataError naming the manifest, the split and the splits it lists when `split` is not
  // one of them ("" = all: always fine). For every command that takes --split, so a typo
  // is named instead of giving an empty result.
  void require_split(const std::string& split) const;
  // The one split whose shards hold `keys`, by the key ranges (first_key … last_key) the
  // manifest records: reads no shard, so a command given a submission and no split takes
  // the split its keys are tiles of. nullopt when they fall in no split or in several;
  // `why` then says which ("none of its 2 keys is a tile of …" / "(test: 10, train: 1)").
  std::optional<std::string> split_of_keys(const std::vector<std::string>& keys, std::string& why) const;
  // Checks that a split can be trusted before it is scored: the manifest lists it, every
  // shard listed for it is present with its recorded size (and, when `hash`, its sha256;
  // a folder shard's digest over its files), and the split's folder holds nothing the
  // manifest does not list (a shard or tile folder left by an earlier run). DataError or
  // IoError naming the file, the shard and what the manifest says.
  SplitVerification verify_split(const std::string& split, bool hash) const;
  // Every tile of one shard entry (tar: the members in order, grouped by key).
  std::vector<DatasetTile> read_shard(const ShardEntry& shard) const;

 private:
  std::filesystem::path root_;
  Manifest manifest_;
};

}  // namespace nsg::io

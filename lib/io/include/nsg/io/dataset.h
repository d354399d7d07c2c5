#pragma once
// Reading a NuScenesGraph dataset (docs/dataset-format.md) for validate, preview, score and the
// model: the manifest, and the tiles of a split streamed shard by shard (tar or folder
// layout) as raw member bytes plus their decoded graph and meta.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nsg/io/raster.h"

namespace nsg::io {

struct DatasetTile {
  std::string key;
  std::string shard;                                  // manifest shard name, e.g. "test-000000"
  std::map<std::string, std::vector<uint8_t>> files;  // suffix ("lidar.tif", "meta.json", …) → bytes
  bool has(const std::string& suffix) const { return files.count(suffix) > 0; }
  // Decoders; ParseError naming "<key>.<suffix>" when missing or malformed.
  Raster raster(const std::string& suffix) const;
  nlohmann::json json(const std::string& suffix) const;
};

// <root>/<relative> for a path the manifest gives (a shard's file or folder). ParseError
// naming <root>/manifest.json and `record` when it is empty, absolute or has '..'
// components: a manifest may not point outside its dataset.
std::filesystem::path path_in_dataset(const std::filesystem::path& root, const std::string& relative,
                                      const std::string& record);

class Dataset {
 public:
  // Reads <root>/manifest.json; IoError / ParseError naming it.
  static Dataset open(const std::filesystem::path& root);

  const std::filesystem::path& root() const { return root_; }
  const nlohmann::json& manifest() const { return manifest_; }
  bool tar_layout() const { return tar_; }
  // Shard entries of the manifest for `split` ("" = all), in manifest order.
  std::vector<nlohmann::json> shards(const std::string& split = "") const;
  // Calls fn for every tile of `split` ("" = all) in manifest order, one shard in memory
  // at a time. Stops early when fn returns false.
  void for_each_tile(const std::string& split, const std::function<bool(const DatasetTile&)>& fn) const;
  // Every tile of one shard entry (tar: the members in order, grouped by key).
  std::vector<DatasetTile> read_shard(const nlohmann::json& shard) const;

 private:
  std::filesystem::path root_;
  nlohmann::json manifest_;
  bool tar_ = true;
};

}  // namespace nsg::io

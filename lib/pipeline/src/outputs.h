#pragma once
// The output side of a share (private to the pipeline): tile shards (tar or folders),
// the maps of a location, and the share's done-record, rewritten after every item.
#include <cstdint>
#include <functional>
#include <filesystem>
#include <map>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "nsg/core/output_folder.h"
#include "nsg/pipeline/config.h"
#include "nsg/pipeline/done_record.h"
#include "nsg/pipeline/generate.h"
#include "nsg/pipeline/tile_files.h"
#include "nsg/tiling/tile.h"
#include "plan.h"

namespace nsg {
class Progress;
}
namespace nsg::nuscenes {
class Database;
}
namespace nsg::graph {
struct LaneGraph;
}

namespace nsg::pipeline {

// Names of the scenes whose sweeps a tile holds (Tile::sweeps), in scene-table order.
std::vector<std::string> scene_names(const nuscenes::Database& db, const std::vector<int32_t>& sweeps);

// parts/share-<i>-of-<n>.json
std::filesystem::path done_record_path(const std::filesystem::path& out, const ShareSpec& share);
// The item digest of its files: a single file's sha256, or the sha256 of
// "<file>\0<sha256>\n" lines.
std::string item_digest(const std::vector<DoneFile>& files);
// Re-hashes the recorded files; false (with `why`) when one is missing or differs.
bool verify_item(const std::filesystem::path& out, const DoneItem& item, std::string* why);
// sha256 of the config's JSON with `dataroot` absolute and resolved (however it was spelled).
std::string config_digest(const GenerateConfig& config);
// The terms a dataset built from a nuScenes release inherits (its sensor data and map
// expansion are CC BY-NC-SA 4.0): the manifest's `licence`, printed once by generate. A
// synthetic release is byte-faithful to the real one and cannot be told apart, so every
// dataset records them.
nlohmann::ordered_json data_licence_json();
std::string data_licence_line();
// The files (relative to `out`) that a dataset of ours in `out` lists: every share
// record's items, the records themselves, and a generate manifest with its shards and maps.
std::set<std::string> dataset_files_listed(const std::filesystem::path& out);
// Removes the dataset of ours in `out` (the files dataset_files_listed names, under
// manifest.json, shards/, tiles/, maps/, parts/) through OutputFolder::remove_listed:
// ConfigError naming `option` and any other file found there, before anything is removed.
int64_t remove_our_dataset(const std::filesystem::path& out, const std::string& option);
// Before a run writes into `out`: a dataset there from another config (or of unknown
// config: a manifest or shards without share records) would leave its shards beside the
// new ones, and a scorer would meet them. Refused (ConfigError naming the folder and
// --overwrite) unless `overwrite`, which first removes the dataset's own entries
// (remove_our_dataset: only files its manifest or records list; any other file
// there refuses the run). A rerun of the same
// config resumes as before.
void prepare_output_folder(const std::filesystem::path& out, const GenerateConfig& config, const ShareSpec& share,
                           bool overwrite);

class OutputWriter {
 public:
  OutputWriter(std::filesystem::path out, const GenerateConfig& config, ShareSpec share);

  std::string shard_item_id(const PlannedShard& shard) const;
  // True when an earlier run of this share (same config) recorded the item and its files
  // still hash the same; the item is then carried into the new record.
  bool verified(const std::string& id);
  void add_plan(nlohmann::ordered_json location_plan);
  void write_maps(const std::string& id, const std::string& location, const graph::LaneGraph& graph,
                  const LocationPlan& plan);
  // Returns the number of tiles written. `progress` (may be null) advances per tile, its
  // detail showing the MB written by this writer so far.
  size_t write_shard(const std::string& id, const nuscenes::Database& db, const LocationPlan& plan,
                     const PlannedShard& shard, const tiling::LocationRasters& layers, const GenerateRun& run,
                     Progress* progress);
  // Writes the tiles i in [shard.first, shard.first + shard.count) in key order, `encode(i)`
  // giving tile i's files (called in parallel batches, so memory stays at one batch and the
  // bytes do not depend on the thread count); the folder layout puts them under
  // tiles/<folder>/<key>/. Returns the number of tiles written.
  size_t write_tiles(const std::string& id, const PlannedShard& shard, const std::string& location,
                     const std::string& folder, const std::function<std::vector<TileFile>(size_t)>& encode,
                     const GenerateRun& run, Progress* progress);
  // Bytes of tile files written by this writer (this run; tar headers not counted).
  uint64_t bytes_written() const { return bytes_written_; }
  // Marks the record complete (with the whole plan) and writes it.
  void finish();

 private:
  void record_item(DoneItem item);
  void save(bool complete);

  std::filesystem::path out_;
  OutputFolder folder_;  // every file of the share is written through it (no link followed out)
  const GenerateConfig& config_;
  ShareSpec share_;
  std::string config_digest_;
  std::map<std::string, DoneItem> previous_;  // items of an earlier record with this config
  std::vector<DoneItem> items_;
  nlohmann::ordered_json plans_ = nlohmann::ordered_json::array();
  uint64_t bytes_written_ = 0;
};

}  // namespace nsg::pipeline

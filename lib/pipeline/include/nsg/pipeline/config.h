#pragma once
// The configuration of `generate`: one JSON document whose keys are declared once, in the
// options tables of the stages (nsg/core/options.h) and below for the run's own keys.
// From that declaration come the reader of a config file, --set and the flags, the range
// errors (naming the key and the file or flag), the resolved config (--print-config, the
// manifest), --list-options, schemas/v1/generate-config.schema.json and
// samples/generate.json (tests check both equal what the declaration gives).
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nsg/core/options.h"
#include "nsg/pipeline/ladder.h"
#include "nsg/graph/lane_graph.h"
#include "nsg/raster/accumulate.h"
#include "nsg/raster/color_layer.h"
#include "nsg/tiling/crops.h"
#include "nsg/tiling/regions.h"

namespace nsg::pipeline {

enum class Layout { kTar, kFolder };

struct OutputOptions {
  Layout layout = Layout::kTar;
  // Shards hold a fixed number of tiles so that every process of a distributed run can
  // name its shards without seeing the others' bytes; 0 = derived from the target size
  // with `estimated_tile_kb` per tile.
  int64_t tiles_per_shard = 0;
  double shard_target_mb = 256.0;
  double estimated_tile_kb = 400.0;
  int deflate_level = 1;
  int64_t resolved_tiles_per_shard() const;
};

// A scene left out of the run (config `scenes.exclude`): its sweeps, camera images and
// boxes contribute nothing. The manifest lists the ones present in the release.
struct ExcludedScene {
  std::string name;    // scene.name, e.g. "scene-0499"
  std::string reason;  // why, for the manifest and the log
};
// The real release's known-bad boston-seaport scenes (devkit README, map_api blacklist;
// docs/nuscenes-input.md): 499, 515, 517 fit the map badly, 501, 502 lie outside it.
std::vector<ExcludedScene> default_excluded_scenes();

// How a location's tiles are given splits: by region (splits.*, geographic: no pixel of
// one split near another's), or by capture date (train from the scenes before
// splits.before_after_date, test from those on or after it: the same streets in both, the
// temporal question; docs/generating.md).
// map-update: splits by region as `regions`, every tile's layers from the scenes captured on
// or after splits.before_after_date, and beside each tile's graph (the current map) the
// prior map's graph with every edge's change label (docs/generating.md "Map update").
enum class SplitPreset { kRegions, kBeforeAfter, kMapUpdate };

struct GenerateConfig {
  std::string dataroot;
  std::string version = "v1.0-trainval";
  std::vector<std::string> locations;  // empty = every location with a log in the release
  std::vector<ExcludedScene> exclude_scenes = default_excluded_scenes();  // [] = keep every scene
  uint64_t seed = 1;
  double resolution_m = 0.2;
  raster::RasterOptions raster;  // LiDAR filters, detections file, camera options
  graph::LaneGraphOptions graph;
  tiling::SplitOptions splits;                                 // ratios, buffer, automatic blocks (regions: below)
  std::map<std::string, std::vector<tiling::Region>> regions;  // explicit regions per location
  SplitPreset split_preset = SplitPreset::kRegions;
  std::string split_date;  // YYYY-MM-DD (log.date_captured) of splits.preset before-after or map-update
  // splits.prior_maps: the folder of the prior map expansion files (<location>.json) of
  // splits.preset map-update; "" = <dataroot>/maps/prior/expansion (a synthetic release's).
  std::string prior_maps;
  tiling::CropOptions crops;
  OutputOptions output;
  LadderOptions ladder;  // the observation ladder (nsg/pipeline/ladder.h)

  double crop_size_m() const { return resolution_m * crops.size_px; }
  tiling::SplitOptions split_options_for(const std::string& location) const;
  // What one key cannot say alone (splits against the crop size, explicit regions);
  // ConfigError naming the key and, from `origins`, where its value came from.
  void check_relations(const options::Origins& origins = {}) const;
  // splits.preset against splits.before_after_date and splits.regions; ConfigError.
  void check_split_preset() const;
  // The inputs a run needs (dataroot, version); ConfigError naming the flag.
  void check_inputs() const;
  // For a config built in code: every declared check, the relations and (when
  // `require_inputs`) the inputs. A config read through the declarations is checked already.
  void validate(bool require_inputs = true) const;
};

// Every key of the generate config, in the order of the resolved document.
const options::Table<GenerateConfig>& generate_option_table();

// Applies a config document over `config` (its keys only; unknown keys and bad values are
// ConfigErrors naming `source` and the key). Records the source of each key in `origins`.
void apply_config_json(GenerateConfig& config, const nlohmann::json& doc, const std::string& source,
                       options::Origins* origins = nullptr);
// Reads a config document over `base` and checks the relations.
GenerateConfig config_from_json(const nlohmann::json& doc, const std::string& file_label, GenerateConfig base = {});
// Parses a config file (ParseError naming it) and applies it.
void apply_config_file(GenerateConfig& config, const std::filesystem::path& file, options::Origins* origins = nullptr);
GenerateConfig load_generate_config(const std::filesystem::path& file);
// The config of a command line (options::resolve_config's precedence: the defaults, the
// file, each --set "key=value", then the flags); the relations are checked last, naming
// the source of the key.
GenerateConfig resolve_generate_config(const std::filesystem::path& file, const std::vector<std::string>& settings,
                                       const std::vector<options::FlagValue>& flags = {},
                                       options::Origins* origins = nullptr);
// The resolved config as written to the manifest and by --print-config (declaration order).
nlohmann::ordered_json config_to_json(const GenerateConfig& config);
// The JSON Schema of the config (schemas/v1/generate-config.schema.json).
nlohmann::ordered_json generate_config_schema();

}  // namespace nsg::pipeline

#pragma once
// The configuration of `generate` (issue 6): one JSON document (samples/generate.json is
// the default; schemas/v1/generate-config.schema.json describes it), every value also
// settable from the command line, printed resolved by --print-config and recorded in
// the manifest.
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

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
  void validate() const;
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

struct GenerateConfig {
  std::string dataroot;
  std::string version = "v1.0-trainval";
  std::vector<std::string> locations;  // empty = every location with a log in the release
  std::vector<ExcludedScene> exclude_scenes = default_excluded_scenes();  // [] = keep every scene
  uint64_t seed = 1;
  double resolution_m = 0.2;
  raster::RasterOptions raster;        // LiDAR filters, detections file, camera options
  graph::LaneGraphOptions graph;
  tiling::SplitOptions splits;         // ratios, buffer, automatic blocks (regions: below)
  std::map<std::string, std::vector<tiling::Region>> regions;  // explicit regions per location
  tiling::CropOptions crops;
  OutputOptions output;

  double crop_size_m() const { return resolution_m * crops.size_px; }
  tiling::SplitOptions split_options_for(const std::string& location) const;
  // ConfigError naming the field; inputs (dataroot, version) only when `require_inputs`.
  void validate(bool require_inputs = true) const;
};

// Reads a config document over the defaults. Unknown keys and wrong types are errors
// naming the file and the key path (a typo must not silently fall back to a default).
GenerateConfig config_from_json(const nlohmann::json& doc, const std::string& file_label,
                                GenerateConfig base = {});
GenerateConfig load_generate_config(const std::filesystem::path& file);
// Sets one value by dotted path ("crops.min_lidar_coverage=0.4"), as from --set.
void apply_setting(GenerateConfig& config, const std::string& assignment);
// The resolved config as written to the manifest and by --print-config (stable key order).
nlohmann::ordered_json config_to_json(const GenerateConfig& config);

}  // namespace nsg::pipeline

#pragma once
// The layers a location's tiles are cut from (private to the pipeline): one source of every
// scene for every split, or with splits.preset before-after two — the scenes captured
// before the date for train, those on or after it for test — each with its own LiDAR,
// vehicle and camera layers, its own region and its own crops.
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nsg/nuscenes/token.h"
#include "nsg/pipeline/config.h"
#include "nsg/raster/accumulate.h"
#include "nsg/raster/color_layer.h"
#include "nsg/tiling/crops.h"
#include "nsg/tiling/regions.h"
#include "plan.h"

namespace nsg::nuscenes {
class Database;
}

namespace nsg::pipeline {

struct LayerSource {
  std::string name;  // "all scenes", "before <date>", "from <date>"
  std::vector<nuscenes::Index> scenes;
  std::vector<std::string> splits;  // the splits it makes tiles of; empty = every split
  raster::LocationLayers layers;
  raster::ColorLayer color{0.2};  // the camera layers over its tiles (camera stage)
  bool serves(const std::string& split) const;
};

// The sources of a location's `scenes` (table order) for the config's split preset.
std::vector<LayerSource> layer_sources(const nuscenes::Database& db, const GenerateConfig& config,
                                       const std::vector<nuscenes::Index>& scenes);
// The source that makes tiles of `split` (InternalError when none does).
const LayerSource& source_for(const std::vector<LayerSource>& sources, const std::string& split);

// splits.preset before-after: per source one region over the cells its LiDAR covers (named
// "train-before" / "test-after"), and its crops planned on its own layers; crop stats per
// split come from the source of that split.
void plan_time_split(const std::vector<LayerSource>& sources, const GenerateConfig& config, uint64_t seed,
                     std::vector<tiling::Region>& regions, std::vector<tiling::Crop>& crops, tiling::CropStats* stats);

// The sides of a before-after split (plan.h's TimeSplitSides): scene counts and the capture
// dates of every scene of the sources.
TimeSplitSides time_split_sides(const nuscenes::Database& db, const std::vector<LayerSource>& sources);

// How far the test tiles of a time split are from the train tiles (they share streets by
// design): the share of test tiles overlapping a train tile, and the median distance from a
// test tile's centre to the nearest train tile's centre.
struct TimeSplitLeakage {
  int64_t test_tiles = 0, overlapping_train = 0;
  std::optional<double> median_distance_m;  // none without train or test tiles
};
TimeSplitLeakage time_split_leakage(const std::vector<tiling::Crop>& crops, double resolution_m, int size_px);

// The location plan's "time_split" record (absent with the regions preset).
nlohmann::ordered_json time_split_json(const GenerateConfig& config, const std::vector<LayerSource>& sources,
                                       const TimeSplitLeakage& leakage);

}  // namespace nsg::pipeline

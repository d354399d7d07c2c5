#pragma once
// `nsgraph stats`: the dataset's key figures (the paper's Table I: labeled area, vehicles,
// semantic classes, lane segments) plus tiles and coverage per split.
#include <cstdint>
#include <filesystem>
#include <map>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

namespace nsg::io {

struct SplitStats {
  int64_t tiles = 0;
  // Every figure but the coverage is measured on the union of the split's tiles, so
  // overlapping crops count each place once (the paper's Table I figures).
  double labeled_area_km2 = 0.0;   // the tiles' footprints
  int64_t lane_segments = 0;       // directed graph edges, each in the tile first covering its middle
  double lane_length_km = 0.0;     // lane centreline length
  int64_t vehicle_px = 0;          // pixels a vehicle drove over
  double vehicle_area_km2 = 0.0;   // vehicle_px × pixel area
  std::set<int> semantic_classes;  // class ids present in the semantic layers (names in JSON and text)
  double mean_coverage_lidar = 0.0, mean_coverage_rgb = 0.0, mean_coverage_semantic = 0.0;
};

struct DatasetStats {
  std::map<std::string, SplitStats> splits;  // train, val, test, and "all"
};

// Reads every tile of the dataset (one shard in memory at a time); `progress`: a progress
// line over the tiles on stderr (the CLI's).
DatasetStats compute_stats(const std::filesystem::path& dataset, bool progress = false);
nlohmann::ordered_json stats_json(const DatasetStats& stats);
std::string stats_text(const DatasetStats& stats);

}  // namespace nsg::io

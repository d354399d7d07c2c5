#pragma once
// The plan of a run (private to the pipeline): per location its regions, ordered crops,
// keys and shards; and the work items in their stable order.
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nsg/pipeline/config.h"
#include "nsg/tiling/crops.h"
#include "nsg/tiling/regions.h"

namespace nsg::pipeline {

struct PlannedShard {
  std::string name;  // "<split>-NNNNNN"
  std::string split;
  size_t first = 0;  // index into LocationPlan::crops
  size_t count = 0;
};

// A shard of ladder rung tiles (generate --ladder): the rung tiles of one split shard's
// crops, named and keyed after it (nsg/pipeline/ladder.h).
struct RungShard {
  PlannedShard shard;  // name "<split>-r<k>-NNNNNN"; first/count as the split shard's
  int rung = 1;
};

struct LocationPlan {
  std::string location;
  std::string map_version;
  size_t graph_nodes = 0, graph_edges = 0, graph_lanes = 0, map_defects = 0;
  size_t scenes_used = 0;
  std::vector<ExcludedScene> excluded_scenes;  // present at the location, left out by the config
  std::vector<tiling::Region> regions;
  std::vector<tiling::Crop> crops;  // train, then val, then test; plan order inside a split
  std::vector<std::string> keys;    // one per crop
  std::vector<PlannedShard> shards;
  std::vector<RungShard> rung_shards;  // after every split shard; empty without a ladder
  nlohmann::ordered_json time_split;   // splits.preset before-after: date, scenes, leakage; else null
  nlohmann::ordered_json map_update;   // splits.preset map-update: date, prior map, lanes by label; else null
  size_t count(const std::string& split) const;
};

// How a location's plan came to its crops: what each filter of the region and crop
// planning took (tiling's stats), kept after the location's layers are gone so the end of
// the run can explain an empty dataset or an empty split. Every share computes the same.
// Under splits.preset before-after: the location's scenes on each side of the date
// (splits.before_after_date) and the capture dates they span (for an empty split's
// explanation).
struct TimeSplitSides {
  std::string first_date, last_date;  // "" without scenes
  size_t before = 0, after = 0;       // scenes captured before the date / on or after it
};

struct PlanFilters {
  std::string location;
  size_t scenes_used = 0, scenes_excluded = 0;
  tiling::RegionStats regions;  // the regions preset's automatic split
  tiling::CropStats crops;
  std::optional<TimeSplitSides> time_split;  // the before-after preset's sides instead of regions
};

// The message of a run whose plan holds no tile at all: per location, which filter dropped
// the candidates and how many, then what to change.
std::string explain_empty_plan(const std::vector<PlanFilters>& filters, const GenerateConfig& config);
// Warning lines for splits that end with no tile while others have tiles (only splits the
// config asks for: a ratio > 0 or explicit regions of the split); empty when none.
std::vector<std::string> empty_split_warnings(const std::vector<PlanFilters>& filters, const GenerateConfig& config);

enum class ItemKind { kMaps, kShard, kRungShard };

struct WorkItem {
  ItemKind kind = ItemKind::kMaps;
  size_t location = 0;  // index into the plan's locations
  size_t shard = 0;     // index into LocationPlan::shards (kShard) or rung_shards (kRungShard)
  std::string id;       // "maps/<location>" or "shards/<split>-NNNNNN.tar" / "tiles/<split>-NNNNNN"
};

// The plan as it is recorded (done-records, manifest): regions, counts, shards.
nlohmann::ordered_json plan_json(const LocationPlan& plan);

// Orders the plan's crops by split (train, val, test), names them (keys) and cuts shards of
// `per_shard`, numbered per split across the run's locations (`next_shard`).
void assign_keys_and_shards(LocationPlan& plan, int64_t per_shard, std::map<std::string, int64_t>& next_shard);

// The rung shards of the ladder's splits: for each split shard of a covered split, one per
// built rung (rung-major within the location).
std::vector<RungShard> plan_rung_shards(const LocationPlan& plan, const LadderOptions& ladder);

}  // namespace nsg::pipeline

#include <algorithm>

#include "nsg/core/strings.h"
#include "nsg/io/manifest.h"
#include "nsg/pipeline/ladder.h"
#include "nsg/tiling/tile.h"
#include "plan.h"

namespace nsg::pipeline {

using nlohmann::ordered_json;

size_t LocationPlan::count(const std::string& split) const {
  return static_cast<size_t>(
      std::count_if(crops.begin(), crops.end(), [&](const tiling::Crop& c) { return c.split == split; }));
}

ordered_json plan_json(const LocationPlan& p) {
  ordered_json regions = ordered_json::array();
  for (const tiling::Region& r : p.regions)
    regions.push_back(io::region_to_json(
        {r.name, r.split, {r.bounds.x_west_m, r.bounds.y_south_m, r.bounds.x_east_m, r.bounds.y_north_m}}));
  ordered_json counts = ordered_json::object();
  for (std::string_view s : tiling::kSplitNames) counts[std::string(s)] = p.count(std::string(s));
  ordered_json shards = ordered_json::array();
  for (const PlannedShard& s : p.shards)
    shards.push_back({{"name", s.name},
                      {"split", s.split},
                      {"tiles", s.count},
                      {"first_key", p.keys[s.first]},
                      {"last_key", p.keys[s.first + s.count - 1]}});
  ordered_json excluded = ordered_json::array();
  for (const ExcludedScene& e : p.excluded_scenes) excluded.push_back({{"name", e.name}, {"reason", e.reason}});
  ordered_json doc = {
      {"name", p.location},
      {"map_version", p.map_version},
      {"lane_graph",
       {{"nodes", p.graph_nodes}, {"edges", p.graph_edges}, {"lanes", p.graph_lanes}, {"map_defects", p.map_defects}}},
      {"scenes", {{"used", p.scenes_used}, {"excluded", excluded}}},
      {"regions", regions},
      {"counts", counts},
      {"shards", shards}};
  if (!p.time_split.is_null()) doc["time_split"] = p.time_split;
  if (p.rung_shards.empty()) return doc;
  ordered_json rung_shards = ordered_json::array();
  for (const RungShard& r : p.rung_shards)
    rung_shards.push_back({{"name", r.shard.name},
                           {"split", r.shard.split},
                           {"rung", r.rung},
                           {"tiles", r.shard.count},
                           {"first_key", rung_key(p.keys[r.shard.first], r.rung)},
                           {"last_key", rung_key(p.keys[r.shard.first + r.shard.count - 1], r.rung)}});
  doc["rung_shards"] = rung_shards;
  return doc;
}

// Orders crops by split (train, val, test), names them and cuts shards of `per_shard`.
void assign_keys_and_shards(LocationPlan& plan, int64_t per_shard, std::map<std::string, int64_t>& next_shard) {
  std::vector<tiling::Crop> ordered;
  for (std::string_view split : tiling::kSplitNames) {
    const size_t first = ordered.size();
    for (const tiling::Crop& c : plan.crops)
      if (c.split == split) ordered.push_back(c);
    for (size_t i = first; i < ordered.size(); ++i)
      plan.keys.push_back(tiling::tile_key(plan.location, std::string(split), static_cast<int64_t>(i - first)));
    for (size_t i = first; i < ordered.size(); i += static_cast<size_t>(per_shard)) {
      PlannedShard s;
      s.split = std::string(split);
      s.name = s.split + "-" + strprintf("%06lld", static_cast<long long>(next_shard[s.split]++));
      s.first = i;
      s.count = std::min(static_cast<size_t>(per_shard), ordered.size() - i);
      plan.shards.push_back(s);
    }
  }
  plan.crops = std::move(ordered);
}

}  // namespace nsg::pipeline

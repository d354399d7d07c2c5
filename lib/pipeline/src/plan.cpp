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

// The location's record as the manifest holds it (io::location_to_json, the manifest's one
// writer); done-records carry it and merge copies it.
ordered_json plan_json(const LocationPlan& p) {
  io::ManifestLocation loc;
  loc.name = p.location;
  loc.map_version = p.map_version;
  loc.lane_graph = {static_cast<int64_t>(p.graph_nodes), static_cast<int64_t>(p.graph_edges),
                    static_cast<int64_t>(p.graph_lanes), static_cast<int64_t>(p.map_defects)};
  io::LocationScenes scenes{static_cast<int64_t>(p.scenes_used), {}};
  for (const ExcludedScene& e : p.excluded_scenes) scenes.excluded.push_back({e.name, "", e.reason});
  loc.scenes = std::move(scenes);
  for (const tiling::Region& r : p.regions)
    loc.regions.push_back(
        {r.name, r.split, {r.bounds.x_west_m, r.bounds.y_south_m, r.bounds.x_east_m, r.bounds.y_north_m}});
  loc.counts = {static_cast<int64_t>(p.count("train")), static_cast<int64_t>(p.count("val")),
                static_cast<int64_t>(p.count("test"))};
  for (const PlannedShard& s : p.shards)
    loc.shards.push_back(
        {s.name, s.split, 0, static_cast<int64_t>(s.count), p.keys[s.first], p.keys[s.first + s.count - 1]});
  loc.time_split = p.time_split;
  loc.map_update = p.map_update;
  for (const RungShard& r : p.rung_shards)
    loc.rung_shards.push_back({r.shard.name, r.shard.split, r.rung, static_cast<int64_t>(r.shard.count),
                               rung_key(p.keys[r.shard.first], r.rung),
                               rung_key(p.keys[r.shard.first + r.shard.count - 1], r.rung)});
  return io::location_to_json(loc);
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

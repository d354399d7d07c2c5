#pragma once
// The observation ladder's checks of `validate` (check "ladder.rungs"): every rung tile is
// its split tile rebuilt from fewer scenes — same crop, region and graph, scenes a subset of
// the split tile's and no more than its rung — and the manifest's rung counts hold.
#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nsg/io/dataset.h"
#include "nsg/io/manifest.h"
#include "nsg/io/tile_meta.h"
#include "raster_values.h"

namespace nsg::validate {

// What the ladder check needs of one tile, split tile or rung tile, as validate read it.
struct LadderTileFacts {
  std::string key, shard;
  int shard_rung = 0;                // the rung of the shard holding the tile; 0 = a split shard
  std::optional<io::TileMeta> meta;  // nullopt when meta.json did not read
  std::string graph_digest;          // sha256 of graph.json less its "key"; empty when unread
};

// The facts of a tile read from `shard` (a split shard or a rung shard).
// `meta`: the tile's meta as its reader gave it; `graph`: graph.json as parsed.
LadderTileFacts ladder_facts(const io::DatasetTile& tile, const io::ShardEntry& shard,
                             const std::optional<io::TileMeta>& meta, const std::optional<nlohmann::json>& graph);

// sha256 of a tile graph document without its "key" (a rung tile's graph is its split
// tile's under another key).
std::string graph_digest_without_key(nlohmann::json graph);

// Reports under "ladder.rungs" (subject: "<shard>/<key>" or the manifest path).
// `found_per_shard`: tiles read per shard name.
void check_ladder_tiles(const io::Ladder& ladder, const std::vector<LadderTileFacts>& tiles,
                        const std::map<std::string, int64_t>& found_per_shard, const ReportFinding& report);

}  // namespace nsg::validate

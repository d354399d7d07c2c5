#include "ladder_checks.h"

#include <algorithm>
#include <set>

#include "nsg/core/error.h"
#include "nsg/core/sha256.h"
#include "nsg/core/strings.h"

namespace nsg::validate {

using nlohmann::json;

std::string graph_digest_without_key(json graph) {
  if (graph.is_object()) graph.erase("key");
  return sha256_hex(graph.dump());
}

LadderTileFacts ladder_facts(const io::DatasetTile& t, const io::ShardEntry& shard,
                             const std::optional<io::TileMeta>& meta, const std::optional<json>& graph) {
  LadderTileFacts f;
  f.key = t.key;
  f.shard = t.shard;
  f.shard_rung = shard.rung;
  f.meta = meta;  // nullopt when it did not read: meta.schema reports it
  if (graph) f.graph_digest = graph_digest_without_key(*graph);
  return f;
}

namespace {

constexpr const char* kCheck = "ladder.rungs";

// A rung tile against its split tile: key, rung, crop, region, graph and scenes.
void check_rung_tile(const LadderTileFacts& r, const LadderTileFacts* base, const ReportFinding& report) {
  const std::string subject = r.shard + "/" + r.key;
  if (!r.meta) return;  // meta.schema reported it
  const io::TileMeta& m = *r.meta;
  if (!m.ladder) return report(kCheck, subject + ".meta.json:/ladder", "the rung tile's ladder record");
  if (m.ladder->rung != r.shard_rung)
    report(kCheck, subject + ".meta.json:/ladder/rung", strprintf("%d, the rung of its shard", r.shard_rung));
  if (r.key != m.ladder->base_key + "-r" + std::to_string(m.ladder->rung))
    report(kCheck, subject, "the key <base_key>-r<rung> (base_key " + m.ladder->base_key + ")");
  if (base == nullptr || !base->meta)
    return report(kCheck, subject, "a split tile " + m.ladder->base_key + " in the dataset (not found)");
  const io::TileMeta& b = *base->meta;
  if (m.bounds_m != b.bounds_m || m.split != b.split || m.location != b.location || m.region != b.region)
    report(kCheck, subject + ".meta.json", "the crop of " + b.key + " (bounds_m, split, location, region)");
  if (!r.graph_digest.empty() && !base->graph_digest.empty() && r.graph_digest != base->graph_digest)
    report(kCheck, subject + ".graph.json", "the graph of " + b.key);
  const std::set<std::string> seen(b.scenes.begin(), b.scenes.end());
  for (const std::string& s : m.scenes)
    if (!seen.count(s)) report(kCheck, subject + ".meta.json:/scenes", "scenes of " + b.key + " ('" + s + "' is not)");
  if (m.scenes.size() > static_cast<size_t>(m.ladder->rung))
    report(kCheck, subject + ".meta.json:/scenes", strprintf("at most %d scenes (the rung)", m.ladder->rung));
  if (m.ladder->scenes_seen != static_cast<int64_t>(b.scenes.size()))
    report(kCheck, subject + ".meta.json:/ladder/scenes_seen",
           strprintf("%zu, the scenes of %s", b.scenes.size(), b.key.c_str()));
}

// The manifest's ladder counts against the rung tiles found.
void check_rung_counts(const io::Ladder& ladder, const std::map<std::string, int64_t>& found_per_shard,
                       const ReportFinding& report) {
  std::map<int, io::TileShardCount> found_per_rung;
  for (const io::ShardEntry& shard : ladder.shards) {
    const auto it = found_per_shard.find(shard.name);
    const int64_t found = it == found_per_shard.end() ? 0 : it->second;
    if (shard.tiles != found)
      report(kCheck, shard.name + ":tiles",
             strprintf("%lld tiles found, manifest says %lld", static_cast<long long>(found),
                       static_cast<long long>(shard.tiles)));
    found_per_rung[shard.rung].tiles += found;
    ++found_per_rung[shard.rung].shards;
  }
  for (const auto& [rung, n] : found_per_rung) {
    const auto listed = std::find_if(ladder.counts.begin(), ladder.counts.end(),
                                     [rung = rung](const auto& c) { return c.first == rung; });
    if (listed == ladder.counts.end() || listed->second.tiles != n.tiles || listed->second.shards != n.shards)
      report(kCheck, "manifest.json:/ladder/counts/" + std::to_string(rung),
             "equal to " + json({{"shards", n.shards}, {"tiles", n.tiles}}).dump() + " (the rung shards found)");
  }
}

}  // namespace

void check_ladder_tiles(const io::Ladder& ladder, const std::vector<LadderTileFacts>& tiles,
                        const std::map<std::string, int64_t>& found_per_shard, const ReportFinding& report) {
  std::map<std::string, const LadderTileFacts*> base;
  for (const LadderTileFacts& t : tiles)
    if (t.shard_rung == 0) base[t.key] = &t;
  for (const LadderTileFacts& t : tiles) {
    if (t.shard_rung == 0) continue;
    const auto it = t.meta && t.meta->ladder ? base.find(t.meta->ladder->base_key) : base.end();
    check_rung_tile(t, it == base.end() ? nullptr : it->second, report);
  }
  check_rung_counts(ladder, found_per_shard, report);
}

}  // namespace nsg::validate

#include "ladder_tiles.h"

#include <map>
#include <set>

#include "nsg/core/error.h"
#include "nsg/core/log.h"
#include "nsg/core/strings.h"
#include "nsg/core/parallel.h"
#include "nsg/nuscenes/database.h"
#include "nsg/pipeline/ladder.h"
#include "outputs.h"

namespace nsg::pipeline {

std::vector<RungShard> plan_rung_shards(const LocationPlan& plan, const LadderOptions& ladder) {
  std::vector<RungShard> out;
  for (int rung : ladder.built_rungs())
    for (const PlannedShard& s : plan.shards) {
      if (!ladder.covers(s.split)) continue;
      RungShard r;
      r.shard = s;
      r.shard.name = rung_shard_name(s.name, s.split, rung);
      r.rung = rung;
      out.push_back(r);
    }
  return out;
}

namespace {

// The scenes whose sweeps hold a kept point of the crop in the all-scenes layers: the
// scenes that saw the tile (its meta.json "scenes"), in table order.
std::vector<nuscenes::Index> scenes_that_saw(const RungInputs& in, const tiling::Crop& crop) {
  tiling::LocationRasters lidar_only = in.all_scenes;
  lidar_only.color = nullptr;
  lidar_only.graph = nullptr;
  tiling::RasterCounts counts;
  const int size = in.config.crops.size_px;
  (void)tiling::extract_rasters(lidar_only, crop.col0, crop.row0, size, size, &counts);
  std::set<nuscenes::Index> scenes;
  for (int32_t sd : counts.sweeps) scenes.insert(in.db.sample[in.db.sample_data[sd].sample].scene);
  return {scenes.begin(), scenes.end()};
}

struct RungTilePlan {
  std::vector<nuscenes::Index> scenes;  // the rung's scenes, table order
  int64_t scenes_seen = 0;
};

io::TileRung rung_meta(const RungInputs& in, const RungShard& rs, size_t i, const RungTilePlan& p,
                       const std::vector<std::string>& scene_names_used) {
  io::TileRung r;
  r.rung = rs.rung;
  r.base_key = in.plan.keys[i];
  r.order = in.config.ladder.order == LadderOrder::kTime ? "time" : "seeded";
  r.scenes_seen = p.scenes_seen;
  std::map<std::string, std::string> date_of;
  for (nuscenes::Index s : p.scenes) date_of[in.db.scene[s].name] = in.db.log[in.db.scene[s].log].date_captured;
  for (const std::string& name : scene_names_used) r.capture_dates.push_back(date_of[name]);
  return r;
}

}  // namespace

std::vector<std::vector<TileFile>> encode_rung_shard(const RungInputs& in, const RungShard& rs, LadderSummary* work) {
  const PlannedShard& shard = rs.shard;
  std::vector<RungTilePlan> plans(shard.count);
  // The tiles of each scene list, in crop order; a std::map keeps the lists' order fixed.
  std::map<std::vector<nuscenes::Index>, std::vector<size_t>> groups;
  for (size_t k = 0; k < shard.count; ++k) {
    const size_t i = shard.first + k;
    const std::vector<nuscenes::Index> seen = scenes_that_saw(in, in.plan.crops[i]);
    const std::vector<nuscenes::Index> ordered =
        ladder_order(in.db, seen, in.config.ladder.order, in.config.seed, in.plan.keys[i]);
    plans[k] = {rung_scenes(ordered, rs.rung), static_cast<int64_t>(seen.size())};
    groups[plans[k].scenes].push_back(k);
  }
  std::vector<std::vector<TileFile>> encoded(shard.count);
  for (const auto& group : groups) {
    // Named, not a structured binding: a lambda below captures them (C++17 forbids that).
    const std::vector<nuscenes::Index>& scenes = group.first;
    const std::vector<size_t>& members = group.second;
    const raster::LocationLayers layers = accumulate_layers(in.db, in.config, scenes, in.threads);
    std::vector<raster::CellRect> rects;
    const int64_t size = in.config.crops.size_px;
    for (size_t k : members) {
      const tiling::Crop& c = in.plan.crops[shard.first + k];
      rects.push_back({c.col0, c.row0, c.col0 + size, c.row0 + size});
    }
    const raster::ColorLayer color = camera_layers(in.db, in.config, in.cameras, scenes, layers.lidar, rects,
                                                   in.threads, in.plan.location + " " + shard.name);
    // The rung's own layers; its graphs (and a map-update dataset's prior graph and labels)
    // are the split's.
    tiling::LocationRasters rasters = in.all_scenes;
    rasters.lidar = &layers.lidar;
    rasters.color = in.cameras.cameras ? &color : nullptr;
    rasters.vehicles = &layers.vehicles;
    parallel_for(members.size(), in.threads, [&](size_t m) {
      const size_t k = members[m], i = shard.first + k;
      const tiling::Tile tile =
          tiling::extract_tile(rasters, in.plan.location, in.plan.crops[i], rung_key(in.plan.keys[i], rs.rung),
                               in.config.resolution_m, in.config.crops.size_px);
      TileFileOptions options;
      options.deflate_level = in.config.output.deflate_level;
      options.scenes = scene_names(in.db, tile.sweeps);
      options.ladder = rung_meta(in, rs, i, plans[k], options.scenes);
      encoded[k] = encode_tile_files(tile, options);
    });
    if (work) {
      ++work->scene_sets;
      work->sweeps += layers.stats.sweeps;
      work->images += color.stats().images_used;
    }
  }
  if (work) work->tiles += shard.count;
  return encoded;
}

// What the ladder's rung tiles cost beside the split tiles' one pass over every scene.
void log_ladder_work(const GenerateSummary& s) {
  if (s.ladder.tiles == 0) return;
  log::info(
      strprintf("generate: ladder: %zu rung tiles from %zu scene lists read %zu sweeps (%.2f× the %zu of the "
                "all-scenes pass) and %zu images",
                s.ladder.tiles, s.ladder.scene_sets, s.ladder.sweeps,
                s.sweeps > 0 ? static_cast<double>(s.ladder.sweeps) / static_cast<double>(s.sweeps) : 0.0, s.sweeps,
                s.ladder.images));
}

}  // namespace nsg::pipeline

#pragma once
// The ladder's tiles (private to the pipeline; nsg/pipeline/ladder.h declares the options):
// the rung shards of a plan, and the tiles of one rung shard rebuilt from each tile's first
// k scenes.
#include <cstddef>
#include <vector>

#include "nsg/pipeline/config.h"
#include "nsg/pipeline/generate.h"
#include "nsg/pipeline/location_layers.h"
#include "nsg/pipeline/tile_files.h"
#include "nsg/tiling/tile.h"
#include "plan.h"

namespace nsg::nuscenes {
class Database;
}

namespace nsg::pipeline {

// Everything a rung shard's tiles are made from: the location's plan, its layers from every
// scene (to find the scenes that saw each tile) and its lane graph.
struct RungInputs {
  const nuscenes::Database& db;
  const GenerateConfig& config;
  const CameraSetup& cameras;
  const LocationPlan& plan;
  const tiling::LocationRasters& all_scenes;  // lidar, vehicles, graph and its index
  int threads = 0;
};

// The files of every tile of `rung_shard`, index i - first for crop i: each tile's scenes
// are the first `rung` (ladder.order) of the scenes whose sweeps its split tile holds; tiles
// with the same scene list share one accumulation and one camera pass, so the bytes depend on
// neither the thread count nor which share writes the shard.
std::vector<std::vector<TileFile>> encode_rung_shard(const RungInputs& in, const RungShard& rung_shard,
                                                     LadderSummary* work);

// Logs what the ladder's rung tiles cost beside the split tiles' one pass over every scene
// (nothing without a ladder).
void log_ladder_work(const GenerateSummary& summary);

}  // namespace nsg::pipeline

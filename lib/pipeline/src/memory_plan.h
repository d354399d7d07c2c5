#pragma once
// generate's peak-memory estimate, made from the tables before the heavy work so
// that `--max-memory` can refuse a run instead of the kernel killing it half-way.
#include <algorithm>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "nsg/nuscenes/database.h"

namespace nsg::pipeline {

struct GenerateConfig;

struct MemoryEstimate {
  std::string location;        // the location whose stages set the peak
  uint64_t base_bytes = 0;     // the process when estimating: tables, map readers
  uint64_t map_bytes = 0;      // reading the location's map expansion (freed once the graph is built)
  uint64_t lidar_blocks = 0;   // estimated 64 × 64 LiDAR blocks at that location
  uint64_t covered_cells = 0;  // estimated LiDAR cells with data there
  uint64_t lidar_bytes = 0;    // the LiDAR layer (packed: the covered cells)
  uint64_t vehicle_bytes = 0;  // the vehicle layer (packed)
  uint64_t scenes_bytes = 0;   // each thread's dense layers of the scene it accumulates
  uint64_t camera_bytes = 0;   // colour layer, point index and images in flight
  uint64_t colour_bytes = 0;   // of camera_bytes, the colour layer (kept until the tiles are cut)
  uint64_t working_bytes = 0;  // graph, tile and shard buffers (after the camera stage)
  // Reading the map comes first and is gone before the layers grow; the layers live
  // through both later stages; the camera stage's buffers and the tile writer's do not
  // overlap.
  uint64_t total() const {
    return base_bytes +
           std::max(map_bytes, lidar_bytes + vehicle_bytes + scenes_bytes + std::max(camera_bytes, working_bytes));
  }
  std::string describe() const;  // one line: total and its parts
  // The estimated quantities and the plan's measured constants, for checking them against
  // a run (generate -v logs this and what the run measured).
  std::string plan_details() const;
  std::string how_to_lower() const;  // what would make it smaller, largest part first
};

// `scenes`: per location, the scene rows the run accumulates (excluded scenes left out).
// `threads` as generate's (0 = all cores); `cameras`: the camera stage runs.
MemoryEstimate estimate_generate_memory(const nuscenes::Database& db,
                                        const std::map<std::string, std::vector<nuscenes::Index>>& scenes,
                                        const GenerateConfig& config, int threads, bool cameras);

}  // namespace nsg::pipeline

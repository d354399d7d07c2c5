#pragma once
// The files a generate run reads, checked before its first heavy stage: a missing sweep,
// image or mask was found only when the stage reached it (after the LiDAR stage: minutes
// on trainval). `generate --check-inputs` runs only these checks.
#include <cstddef>
#include <string>
#include <vector>

#include "nsg/nuscenes/database.h"
#include "nsg/pipeline/config.h"

namespace nsg::pipeline {

struct InputCounts {
  size_t scenes = 0;  // of the run's locations, not left out
  size_t sweeps = 0;  // of raster.lidar_channel, key frames and sweeps
  size_t images = 0;  // key-frame camera images (when a camera layer is on)
  size_t masks = 0;   // their semantic masks (semantics from masks)
  size_t maps = 0;    // map expansions, one per location
  std::string describe() const;
};

// Checks that every file of `locations`' scenes (those `excluded` does not mark) that the
// run will open is a regular file: the map expansion of each location, each LiDAR sweep,
// and with a camera layer each key-frame image and, for semantics from masks, its mask.
// IoError naming the first missing file, with how many of how many are missing.
// `config.raster.camera.semantic_source` is already concrete (resolve_semantic_source).
InputCounts check_run_inputs(const nuscenes::Database& db, const GenerateConfig& config,
                             const std::vector<std::string>& locations, const std::vector<char>& excluded);

}  // namespace nsg::pipeline

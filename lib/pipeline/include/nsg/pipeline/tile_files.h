#pragma once
// The files of one tile (DESIGN.md §5), in member order: lidar, rgb, semantic, vehicle,
// coverage GeoTIFFs, then graph.json and meta.json — all sharing the tile key.
#include <cstdint>
#include <string>
#include <vector>

#include "nsg/tiling/tile.h"

namespace nsg::pipeline {

struct TileFile {
  std::string name;  // "<key>.<suffix>"
  std::vector<uint8_t> bytes;
};

struct TileFileOptions {
  int deflate_level = 1;
  std::vector<std::string> scenes;  // names of the scenes whose sweeps the tile holds
};

std::vector<TileFile> encode_tile_files(const tiling::Tile& tile, const TileFileOptions& options);

// The suffixes of a complete tile, in member order.
const std::vector<std::string>& tile_file_suffixes();

}  // namespace nsg::pipeline

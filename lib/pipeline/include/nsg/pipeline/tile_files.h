#pragma once
// The files of one tile (docs/dataset-format.md), in the member order of io::tile_members(): lidar,
// rgb, semantic, vehicle, coverage GeoTIFFs, then graph.json and meta.json — all sharing
// the tile key.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "nsg/io/raster.h"
#include "nsg/io/tile_meta.h"
#include "nsg/io/tile_members.h"
#include "nsg/tiling/tile.h"

namespace nsg::pipeline {

struct TileFile {
  std::string name;  // "<key>.<suffix>"
  std::vector<uint8_t> bytes;
};

struct TileFileOptions {
  int deflate_level = 1;
  std::vector<std::string> scenes;     // names of the scenes whose sweeps the tile holds
  std::optional<io::TileRung> ladder;  // a ladder rung's tile: its meta.json "ladder"
};

std::vector<TileFile> encode_tile_files(const tiling::Tile& tile, const TileFileOptions& options);

// The suffixes of a complete tile, in member order.
const std::vector<std::string>& tile_file_suffixes();

// A raster member's layer of `rasters` (a tile, or a window of any size) as an io::Raster
// of the member's dtype and bands.
io::Raster layer_raster(const tiling::TileRasters& rasters, const io::TileMember& member);

}  // namespace nsg::pipeline

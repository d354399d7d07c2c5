#pragma once
// One tile (docs/dataset-format.md): the five rasters of a crop, row 0 = north, column 0 = west,
// its clipped lane graph and the figures of its meta file.
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "nsg/graph/clip.h"
#include "nsg/tiling/crops.h"

namespace nsg::raster {
class LidarLayer;
class ColorLayer;
class VehicleLayer;
}  // namespace nsg::raster

namespace nsg::graph {
struct LaneGraph;
class SegmentIndex;
}  // namespace nsg::graph

namespace nsg::tiling {

inline constexpr uint8_t kSemanticNoData = 255;

struct TileRasters {
  int size_px = 0;  // width = height of a tile; for other windows see width/height
  int width_px = 0, height_px = 0;
  std::vector<uint8_t> lidar;     // size²: intensity of the kept point; 0 = no data
  std::vector<uint8_t> rgb;       // size² × 3; 0,0,0 = no data
  std::vector<uint8_t> semantic;  // size²: class id; 255 = no data
  std::vector<float> vehicle;     // size²: heading in [0, 1); −1 = no vehicle
  std::vector<uint8_t> coverage;  // size²: bit flags 1 LiDAR, 2 RGB, 4 semantics
};

struct Tile {
  std::string key;  // <location>-<split>-<NNNNNN>
  std::string location;
  Crop crop;
  RectM bounds;
  double resolution_m = 0.2;
  TileRasters rasters;
  graph::TileGraph graph;
  std::optional<graph::TileGraph> prior_graph;  // map-update datasets: the prior map clipped to the tile
  double coverage_lidar = 0.0;                  // fractions of the tile's pixels
  double coverage_rgb = 0.0;
  double coverage_semantic = 0.0;
  int64_t vehicle_px = 0;
  std::vector<int32_t> sweeps;  // distinct source sweeps of the kept points, ascending
};

std::string tile_key(const std::string& location, const std::string& split, int64_t index);

// The layers of one location, as the raster stage produced them.
struct LocationRasters {
  const raster::LidarLayer* lidar = nullptr;
  const raster::ColorLayer* color = nullptr;  // may be null: no RGB / semantics
  const raster::VehicleLayer* vehicles = nullptr;
  const graph::LaneGraph* graph = nullptr;
  const graph::SegmentIndex* graph_index = nullptr;
  // A map-update dataset's (generate's splits.preset map-update): the prior map's lane graph,
  // and every lane token's change label, set on the edges of both tile graphs.
  const graph::LaneGraph* prior_graph = nullptr;
  const graph::SegmentIndex* prior_index = nullptr;
  const std::map<std::string, graph::MapChange>* changes = nullptr;
};

// Counts of the pixels holding data, from extract_rasters.
struct RasterCounts {
  size_t lidar = 0, rgb = 0, semantic = 0, vehicle = 0;
  std::vector<int32_t> sweeps;  // distinct source sweeps, ascending
};

// The layers over the cell window [col0, col0 + width) × [row0, row0 + height), row 0 =
// north. Reads only the blocks under the window.
TileRasters extract_rasters(const LocationRasters& layers, int64_t col0, int64_t row0, int width_px, int height_px,
                            RasterCounts* counts);

// Cuts a crop out of the location layers. A cell with RGB but a zero colour is stored as
// (0, 0, 1) so that 0,0,0 keeps meaning "no data".
Tile extract_tile(const LocationRasters& layers, const std::string& location, const Crop& crop, const std::string& key,
                  double resolution_m, int size_px);

}  // namespace nsg::tiling

#include "nsg/tiling/tile.h"

#include <algorithm>
#include <cstdio>

#include "nsg/graph/segment_index.h"
#include "nsg/raster/color_layer.h"
#include "nsg/raster/lidar_layer.h"
#include "nsg/raster/vehicle_layer.h"

namespace nsg::tiling {

std::string tile_key(const std::string& location, const std::string& split, int64_t index) {
  char n[16];
  std::snprintf(n, sizeof n, "%06lld", static_cast<long long>(index));
  return location + "-" + split + "-" + n;
}

namespace {

// Pixel (u, v) of the tile ↔ cell (col0 + u, row0 + size − 1 − v): row 0 is the north edge.
template <typename Cell, typename F>
void for_each_pixel(const raster::SparseGrid<Cell>& grid, const Crop& crop, int size, F&& f) {
  for (int v = 0; v < size; ++v) {
    const int64_t row = crop.row0 + size - 1 - v;
    for (int u = 0; u < size; ++u) {
      const Cell* cell = grid.find({crop.col0 + u, row});
      if (cell != nullptr) f(static_cast<size_t>(v) * size + u, *cell);
    }
  }
}

}  // namespace

Tile extract_tile(const LocationRasters& layers, const std::string& location, const Crop& crop,
                  const std::string& key, double resolution_m, int size_px) {
  Tile t;
  t.key = key;
  t.location = location;
  t.crop = crop;
  t.bounds = crop.bounds(resolution_m, size_px);
  t.resolution_m = resolution_m;
  const size_t n = static_cast<size_t>(size_px) * size_px;
  TileRasters& r = t.rasters;
  r.size_px = size_px;
  r.lidar.assign(n, 0);
  r.rgb.assign(n * 3, 0);
  r.semantic.assign(n, kSemanticNoData);
  r.vehicle.assign(n, -1.0f);
  r.coverage.assign(n, 0);

  size_t lidar_px = 0, rgb_px = 0, semantic_px = 0;
  for_each_pixel(layers.lidar->cells(), crop, size_px, [&](size_t i, const raster::LidarCell& c) {
    if (!c.has_data()) return;
    // Intensity 0 is a valid return but the format reserves 0 for "no data".
    r.lidar[i] = std::max<uint8_t>(c.intensity, 1);
    r.coverage[i] |= raster::kCoverageLidar;
    t.sweeps.push_back(c.sweep);
    ++lidar_px;
  });
  if (layers.color != nullptr)
    for_each_pixel(layers.color->cells(), crop, size_px, [&](size_t i, const raster::ColorCell& c) {
      if (c.flags & raster::kCoverageRgb) {
        r.rgb[3 * i] = c.r;
        r.rgb[3 * i + 1] = c.g;
        r.rgb[3 * i + 2] = (c.r | c.g | c.b) == 0 ? 1 : c.b;
        r.coverage[i] |= raster::kCoverageRgb;
        ++rgb_px;
      }
      if ((c.flags & raster::kCoverageSemantic) && c.semantic != kSemanticNoData) {
        r.semantic[i] = c.semantic;
        r.coverage[i] |= raster::kCoverageSemantic;
        ++semantic_px;
      }
    });
  if (layers.vehicles != nullptr)
    for_each_pixel(layers.vehicles->cells(), crop, size_px, [&](size_t i, const raster::VehicleCell& c) {
      if (c.heading < 0.0f) return;
      r.vehicle[i] = c.heading;
      ++t.vehicle_px;
    });
  std::sort(t.sweeps.begin(), t.sweeps.end());
  t.sweeps.erase(std::unique(t.sweeps.begin(), t.sweeps.end()), t.sweeps.end());
  t.coverage_lidar = static_cast<double>(lidar_px) / static_cast<double>(n);
  t.coverage_rgb = static_cast<double>(rgb_px) / static_cast<double>(n);
  t.coverage_semantic = static_cast<double>(semantic_px) / static_cast<double>(n);

  if (layers.graph != nullptr && layers.graph_index != nullptr)
    t.graph = graph::clip_to_tile(*layers.graph, *layers.graph_index,
                                  {t.bounds.x_west_m, t.bounds.y_south_m, t.bounds.x_east_m, t.bounds.y_north_m},
                                  resolution_m);
  return t;
}

}  // namespace nsg::tiling

#include "nsg/tiling/tile.h"

#include <algorithm>
#include <cstdio>

#include "nsg/graph/map_changes.h"
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

// Pixel (u, v) of the window ↔ cell (col0 + u, row0 + height − 1 − v): row 0 is the north edge.
template <typename Cell, typename F>
void for_each_pixel(const raster::SparseGrid<Cell>& grid, int64_t col0, int64_t row0, int width, int height, F&& f) {
  for (int v = 0; v < height; ++v) {
    const int64_t row = row0 + height - 1 - v;
    for (int u = 0; u < width; ++u) {
      const Cell* cell = grid.find({col0 + u, row});
      if (cell != nullptr) f(static_cast<size_t>(v) * width + u, *cell);
    }
  }
}

}  // namespace

TileRasters extract_rasters(const LocationRasters& layers, int64_t col0, int64_t row0, int width, int height,
                            RasterCounts* counts) {
  const size_t n = static_cast<size_t>(width) * height;
  TileRasters r;
  r.size_px = width == height ? width : 0;
  r.width_px = width;
  r.height_px = height;
  r.lidar.assign(n, 0);
  r.rgb.assign(n * 3, 0);
  r.semantic.assign(n, kSemanticNoData);
  r.vehicle.assign(n, -1.0f);
  r.coverage.assign(n, 0);
  RasterCounts local;
  RasterCounts& k = counts != nullptr ? *counts : local;
  k = {};
  for_each_pixel(layers.lidar->cells(), col0, row0, width, height, [&](size_t i, const raster::LidarCell& c) {
    if (!c.has_data()) return;
    // Intensity 0 is a valid return but the format reserves 0 for "no data".
    r.lidar[i] = std::max<uint8_t>(c.intensity, 1);
    r.coverage[i] |= raster::kCoverageLidar;
    k.sweeps.push_back(c.sweep);
    ++k.lidar;
  });
  if (layers.color != nullptr)
    for_each_pixel(layers.color->cells(), col0, row0, width, height, [&](size_t i, const raster::ColorCell& c) {
      if (c.flags & raster::kCoverageRgb) {
        r.rgb[3 * i] = c.r;
        r.rgb[3 * i + 1] = c.g;
        r.rgb[3 * i + 2] = (c.r | c.g | c.b) == 0 ? 1 : c.b;  // 0,0,0 means "no data"
        r.coverage[i] |= raster::kCoverageRgb;
        ++k.rgb;
      }
      if ((c.flags & raster::kCoverageSemantic) && c.semantic != kSemanticNoData) {
        r.semantic[i] = c.semantic;
        r.coverage[i] |= raster::kCoverageSemantic;
        ++k.semantic;
      }
    });
  if (layers.vehicles != nullptr)
    for_each_pixel(layers.vehicles->cells(), col0, row0, width, height, [&](size_t i, const raster::VehicleCell& c) {
      if (c.heading < 0.0f) return;
      r.vehicle[i] = c.heading;
      ++k.vehicle;
    });
  std::sort(k.sweeps.begin(), k.sweeps.end());
  k.sweeps.erase(std::unique(k.sweeps.begin(), k.sweeps.end()), k.sweeps.end());
  return r;
}

Tile extract_tile(const LocationRasters& layers, const std::string& location, const Crop& crop, const std::string& key,
                  double resolution_m, int size_px) {
  Tile t;
  t.key = key;
  t.location = location;
  t.crop = crop;
  t.bounds = crop.bounds(resolution_m, size_px);
  t.resolution_m = resolution_m;
  RasterCounts counts;
  t.rasters = extract_rasters(layers, crop.col0, crop.row0, size_px, size_px, &counts);
  const double n = static_cast<double>(size_px) * size_px;
  t.coverage_lidar = static_cast<double>(counts.lidar) / n;
  t.coverage_rgb = static_cast<double>(counts.rgb) / n;
  t.coverage_semantic = static_cast<double>(counts.semantic) / n;
  t.vehicle_px = static_cast<int64_t>(counts.vehicle);
  t.sweeps = std::move(counts.sweeps);
  const graph::TileBounds box{t.bounds.x_west_m, t.bounds.y_south_m, t.bounds.x_east_m, t.bounds.y_north_m};
  if (layers.graph != nullptr && layers.graph_index != nullptr)
    t.graph = graph::clip_to_tile(*layers.graph, *layers.graph_index, box, resolution_m);
  if (layers.prior_graph != nullptr && layers.prior_index != nullptr) {
    t.prior_graph = graph::clip_to_tile(*layers.prior_graph, *layers.prior_index, box, resolution_m);
    if (layers.changes != nullptr) {
      graph::label_map_changes(t.graph, *layers.changes);
      graph::label_map_changes(*t.prior_graph, *layers.changes);
    }
  }
  return t;
}

}  // namespace nsg::tiling

#pragma once
// A location's BEV layers for a generate config: the raster chain that `generate` runs
// per location and `inspect layers` runs over one window, so both honour every option
// (scenes.exclude, lidar.*, camera.* with either semantic source, vehicles.*).
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "nsg/nuscenes/token.h"
#include "nsg/pipeline/config.h"
#include "nsg/raster/accumulate.h"
#include "nsg/raster/color_layer.h"
#include "nsg/raster/lidarseg_layer.h"
#include "nsg/tiling/tile.h"

namespace nsg::nuscenes {
class Database;
}

namespace nsg::pipeline {

// The scenes of `location` that the config keeps (scenes.exclude left out), table order.
std::vector<nuscenes::Index> location_scenes(const nuscenes::Database& db, const GenerateConfig& config,
                                             const std::string& location);

// The camera stage's inputs beyond the config, loaded and checked once per run (a missing
// lidarseg.json or a bad labels file is a setup question, reported before any work).
struct CameraSetup {
  bool cameras = false;   // any camera layer (camera.rgb or camera.semantic)
  bool lidarseg = false;  // semantics from nuScenes-lidarseg
  raster::LidarsegClassTable lidarseg_classes{};
};
CameraSetup prepare_cameras(const nuscenes::Database& db, const GenerateConfig& config);

// LiDAR and vehicle layers of `scenes` (empty list: empty layers); `progress` (may be
// null) advances per sweep.
raster::LocationLayers accumulate_layers(const nuscenes::Database& db, const GenerateConfig& config,
                                         const std::vector<nuscenes::Index>& scenes, int threads,
                                         Progress* progress = nullptr);

// The camera layers over the cells of `rects` (RGB and mask semantics from the images;
// lidarseg semantics laid over them); empty when the config has no camera layer. `label`
// names the location in warnings.
raster::ColorLayer camera_layers(const nuscenes::Database& db, const GenerateConfig& config, const CameraSetup& setup,
                                 const std::vector<nuscenes::Index>& scenes, const raster::LidarLayer& lidar,
                                 const std::vector<raster::CellRect>& rects, int threads, const std::string& label,
                                 Progress* progress = nullptr);

// One window of a location's layers (inspect layers), cut like a tile: the whole chain
// above over the location's scenes, camera layers over the window only.
struct WindowLayers {
  tiling::CellWindow window;  // cells [col0, col1) × [row0, row1)
  double resolution_m = 0.2;
  tiling::TileRasters rasters;  // width × height of the window
  tiling::RasterCounts counts;
  raster::AccumulateStats stats;
  size_t lidar_layer_bytes = 0;
};
// `bbox_m` = {x_west, y_south, x_east, y_north} in map metres (edges within 1e-9 cell of
// the grid are on it), or nullopt for the extent of the LiDAR cells holding data.
// DataError when the location has no LiDAR; ConfigError (record `bbox_record`) when the
// window holds more than `max_pixels`.
WindowLayers window_layers(const nuscenes::Database& db, const GenerateConfig& config, const std::string& location,
                           const std::optional<std::array<double, 4>>& bbox_m, int64_t max_pixels,
                           const std::string& bbox_record, int threads);

}  // namespace nsg::pipeline

#pragma once
// A location's BEV layers for a generate config: the raster chain that `generate` runs
// per location and `inspect layers` runs over one window, so both honour every option
// (scenes.exclude, lidar.*, camera.* with either semantic source, vehicles.*).
#include <string>
#include <vector>

#include "nsg/nuscenes/token.h"
#include "nsg/pipeline/config.h"
#include "nsg/raster/accumulate.h"
#include "nsg/raster/color_layer.h"
#include "nsg/raster/lidarseg_layer.h"

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

// LiDAR and vehicle layers of `scenes` (empty list: empty layers).
raster::LocationLayers accumulate_layers(const nuscenes::Database& db, const GenerateConfig& config,
                                         const std::vector<nuscenes::Index>& scenes, int threads);

// The camera layers over the cells of `rects` (RGB and mask semantics from the images;
// lidarseg semantics laid over them); empty when the config has no camera layer. `label`
// names the location in warnings.
raster::ColorLayer camera_layers(const nuscenes::Database& db, const GenerateConfig& config, const CameraSetup& setup,
                                 const std::vector<nuscenes::Index>& scenes, const raster::LidarLayer& lidar,
                                 const std::vector<raster::CellRect>& rects, int threads, const std::string& label);

}  // namespace nsg::pipeline

#include "nsg/pipeline/location_layers.h"

#include <set>

#include "nsg/core/log.h"
#include "nsg/core/strings.h"
#include "nsg/nuscenes/database.h"
#include "nsg/nuscenes/lidarseg.h"
#include "nsg/segment/labels.h"

namespace nsg::pipeline {

std::vector<nuscenes::Index> location_scenes(const nuscenes::Database& db, const GenerateConfig& config,
                                             const std::string& location) {
  std::set<std::string> excluded;
  for (const ExcludedScene& e : config.exclude_scenes) excluded.insert(e.name);
  std::vector<nuscenes::Index> out;
  for (nuscenes::Index s : raster::scenes_at(db, location))
    if (!excluded.count(db.scene[s].name)) out.push_back(s);
  return out;
}

CameraSetup prepare_cameras(const nuscenes::Database& db, const GenerateConfig& config) {
  const raster::CameraOptions& camera = config.raster.camera;
  CameraSetup setup;
  setup.cameras = camera.rgb || camera.semantic;
  setup.lidarseg = camera.semantic && camera.semantic_source == raster::SemanticSource::kLidarseg;
  if (setup.lidarseg) {
    setup.lidarseg_classes = camera.lidarseg_labels.empty() ? segment::builtin_lidarseg_labels().table()
                                                            : segment::load_labels(camera.lidarseg_labels).table();
    (void)nuscenes::LidarsegIndex::load(db);
  }
  return setup;
}

raster::LocationLayers accumulate_layers(const nuscenes::Database& db, const GenerateConfig& config,
                                         const std::vector<nuscenes::Index>& scenes, int threads) {
  if (scenes.empty())
    return raster::LocationLayers{raster::LidarLayer(config.resolution_m), raster::VehicleLayer(config.resolution_m), {}};
  return raster::accumulate_scenes(db, scenes, config.raster, threads);
}

raster::ColorLayer camera_layers(const nuscenes::Database& db, const GenerateConfig& config, const CameraSetup& setup,
                                 const std::vector<nuscenes::Index>& scenes, const raster::LidarLayer& lidar,
                                 const std::vector<raster::CellRect>& rects, int threads, const std::string& label) {
  raster::ColorLayer color(config.resolution_m);
  if (!setup.cameras || rects.empty() || scenes.empty()) return color;
  const raster::CameraOptions& camera = config.raster.camera;
  if (camera.rgb || camera.semantic_masks()) color = raster::colorize_scenes(db, scenes, lidar, rects, camera, threads);
  if (setup.lidarseg) {
    const raster::LidarsegLayer labels = raster::accumulate_lidarseg(db, scenes, config.raster.lidar,
                                                                     config.raster.lidar_channel,
                                                                     setup.lidarseg_classes, threads);
    if (labels.stats.sweeps_without_labels > 0)
      log::warn(strprintf("generate: %s: %zu of %zu key-frame sweeps have no lidarseg labels (their points give no "
                          "class)", label.c_str(), labels.stats.sweeps_without_labels, labels.stats.sweeps));
    raster::overlay_semantics(color, labels, rects);
  }
  return color;
}

}  // namespace nsg::pipeline

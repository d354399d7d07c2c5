#include "nsg/pipeline/location_layers.h"

#include <cmath>
#include <set>

#include "nsg/core/error.h"
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
                                         const std::vector<nuscenes::Index>& scenes, int threads, Progress* progress) {
  if (scenes.empty())
    return raster::LocationLayers{
        raster::LidarLayer(config.resolution_m), raster::VehicleLayer(config.resolution_m), {}};
  return raster::accumulate_scenes(db, scenes, config.raster, threads, progress);
}

raster::ColorLayer camera_layers(const nuscenes::Database& db, const GenerateConfig& config, const CameraSetup& setup,
                                 const std::vector<nuscenes::Index>& scenes, const raster::LidarLayer& lidar,
                                 const std::vector<raster::CellRect>& rects, int threads, const std::string& label,
                                 Progress* progress) {
  raster::ColorLayer color(config.resolution_m);
  if (!setup.cameras || rects.empty() || scenes.empty()) return color;
  const raster::CameraOptions& camera = config.raster.camera;
  if (camera.rgb || camera.semantic_masks())
    color = raster::colorize_scenes(db, scenes, lidar, rects, camera, threads, progress);
  if (setup.lidarseg) {
    const raster::LidarsegLayer labels = raster::accumulate_lidarseg(
        db, scenes, config.raster.lidar, config.raster.lidar_channel, setup.lidarseg_classes, threads);
    if (labels.stats.sweeps_without_labels > 0)
      log::warn(
          strprintf("generate: %s: %zu of %zu key-frame sweeps have no lidarseg labels (their points give no "
                    "class)",
                    label.c_str(), labels.stats.sweeps_without_labels, labels.stats.sweeps));
    raster::overlay_semantics(color, labels, rects);
  }
  return color;
}

WindowLayers window_layers(const nuscenes::Database& db, const GenerateConfig& config, const std::string& location,
                           const std::optional<std::array<double, 4>>& bbox_m, int64_t max_pixels,
                           const std::string& bbox_record, int threads) {
  const std::vector<nuscenes::Index> scenes = location_scenes(db, config, location);
  const CameraSetup cameras = prepare_cameras(db, config);
  // inspect layers reads every sweep of the location: minutes on a real city.
  Progress lidar_progress("lidar sweeps", 0);
  const raster::LocationLayers layers = accumulate_layers(db, config, scenes, threads, &lidar_progress);
  lidar_progress.finish();
  WindowLayers out;
  out.resolution_m = layers.lidar.resolution_m();
  out.stats = layers.stats;
  out.lidar_layer_bytes = layers.lidar.cells().memory_bytes();
  if (bbox_m) {
    const double res = out.resolution_m;
    const auto lo = [res](double m) { return static_cast<int64_t>(std::floor(m / res + 1e-9)); };
    const auto hi = [res](double m) { return static_cast<int64_t>(std::ceil(m / res - 1e-9)); };
    const std::array<double, 4>& b = *bbox_m;
    out.window = {lo(b[0]), lo(b[1]), hi(b[2]), hi(b[3])};
  } else {
    out.window = tiling::covered_window(layers.lidar);
    if (out.window.empty()) throw DataError(config.dataroot, "location " + location, "LiDAR points at the location");
  }
  const tiling::CellWindow& w = out.window;
  const int64_t pixels = (w.col1 - w.col0) * (w.row1 - w.row0);
  if (pixels > max_pixels)
    throw ConfigError("", bbox_record,
                      strprintf("a window of at most %lld pixels (this one has %lld; pass a smaller one)",
                                static_cast<long long>(max_pixels), static_cast<long long>(pixels)));
  // Images are read for RGB and mask semantics; lidarseg semantics read none.
  const raster::CameraOptions& camera = config.raster.camera;
  Progress camera_progress("camera images", 0, cameras.cameras && (camera.rgb || camera.semantic_masks()));
  const raster::ColorLayer color =
      camera_layers(db, config, cameras, scenes, layers.lidar, {{w.col0, w.row0, w.col1, w.row1}}, threads, location,
                    &camera_progress);
  camera_progress.finish();
  const tiling::LocationRasters source{&layers.lidar, cameras.cameras ? &color : nullptr, &layers.vehicles, nullptr,
                                       nullptr};
  out.rasters = tiling::extract_rasters(source, w.col0, w.row0, static_cast<int>(w.col1 - w.col0),
                                        static_cast<int>(w.row1 - w.row0), &out.counts);
  return out;
}

}  // namespace nsg::pipeline

#pragma once
// The raster stage over one location of a release (docs/architecture.md, "Vehicles"):
// every LIDAR_TOP sweep (key and non-key) of every scene at the location is read,
// filtered in the sensor frame, moved to the global frame with the sweep's own ego pose
// and binned lowest-z; vehicle boxes come from a detection results file or from the
// vehicle.* annotations. Scenes run in parallel, each thread accumulating one scene at a
// time into its own dense layers and folding it into the shared packed result with the
// layers' order-free merges, so the result is identical at any thread count.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "nsg/core/progress.h"
#include "nsg/nuscenes/token.h"
#include "nsg/raster/color_layer.h"
#include "nsg/raster/lidar_layer.h"
#include "nsg/raster/vehicle_layer.h"

namespace nsg::nuscenes {
class Database;
}

namespace nsg::raster {

struct RasterOptions {
  LidarOptions lidar;  // resolution (shared by both layers), roof square, max range
  // A nuScenes detection results file; empty = boxes from the vehicle.* annotations.
  std::filesystem::path detections_file;
  double detection_score_threshold = 0.3;  // keep detections with score ≥ this
  std::string lidar_channel = "LIDAR_TOP";
  // Camera colouring runs separately (colorize_location), so a cluster share colours only
  // the cells of its own tiles; kept here so one options struct configures the stage.
  CameraOptions camera;
  // The declared checks (raster_options.h) for options built in code; ConfigError naming the key.
  void validate() const;
};

struct AccumulateStats {
  size_t scenes = 0;
  size_t sweeps = 0;  // sample_data files read (key and non-key)
  size_t points_read = 0;
  size_t points_kept = 0;    // after the roof square and the range filter
  size_t vehicle_boxes = 0;  // boxes rasterized (after class / score filtering)
  size_t covered_cells = 0;  // LiDAR cells holding a point
  size_t lidar_blocks = 0;   // allocated 64×64 blocks of the LiDAR layer
};

struct LocationLayers {
  LidarLayer lidar;
  VehicleLayer vehicles;
  AccumulateStats stats;
};

// Rasterizes `location` (log.location) of `db`. `threads` as nsg::parallel_for (0 = all
// cores). Only the detections of the location's samples are used (a results file may hold
// other samples too). Throws ConfigError (bad options), DataError (no scene at the
// location), IoError / ParseError from the sweep and results readers.
LocationLayers accumulate_location(const nuscenes::Database& db, const std::string& location,
                                   const RasterOptions& options, int threads);

// The scenes (scene-table rows, in table order) of `location`; DataError if it has none.
std::vector<nuscenes::Index> scenes_at(const nuscenes::Database& db, const std::string& location);
// accumulate_location over a subset of a location's scenes (export-cloud: one scene), with
// `options` already checked (read through the declarations, or validate()).
// InternalError if `scenes` is empty or spans locations (one map frame per layer): the
// check, check_scene_list, is shared with colorize_scenes. `progress` (may be null)
// advances by one per sweep read, from the worker threads.
void check_scene_list(const nuscenes::Database& db, const std::vector<nuscenes::Index>& scenes);
LocationLayers accumulate_scenes(const nuscenes::Database& db, const std::vector<nuscenes::Index>& scenes,
                                 const RasterOptions& options, int threads, Progress* progress = nullptr);

}  // namespace nsg::raster

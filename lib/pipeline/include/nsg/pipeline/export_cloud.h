#pragma once
// `nsgraph export-cloud`: the accumulated lowest-z ground cloud of ONE scene as a
// PCD file for PCL tools — per 0.2 m cell the lowest point of the scene's sweeps (global map
// metres), its intensity, and the RGB / semantic class the camera stage gives it from the
// scene's own key frames. PCL types stay out of this header (only pcd_writer.cpp sees them).
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "nsg/nuscenes/token.h"
#include "nsg/raster/accumulate.h"

namespace nsg::nuscenes {
class Database;
}

namespace nsg::pipeline {

enum class PcdFormat { kAscii, kBinary, kBinaryCompressed };
// "ascii" | "binary" | "binary_compressed"; ConfigError naming --format otherwise.
PcdFormat parse_pcd_format(const std::string& text);
const char* pcd_format_name(PcdFormat format);

inline constexpr uint32_t kCloudNoLabel = 255;  // the semantic layer's "no class"

// One cell's kept point. rgb is PCL's packed 0xAARRGGBB (A = 255 when the cell has a
// colour, the whole word 0 when no camera saw it); label the semantic class id or
// kCloudNoLabel.
struct CloudPoint {
  float x_m = 0, y_m = 0, z_m = 0;
  float intensity = 0;  // the sweep's 0..255 intensity, as PCL's float field
  uint32_t rgb = 0;
  uint32_t label = kCloudNoLabel;
};

struct SceneCloud {
  std::string scene, location;
  std::vector<CloudPoint> points;  // one per covered cell, sorted by (row, col)
  size_t sweeps = 0;               // LiDAR sample_data of the scene read
  size_t images = 0;               // key-frame camera images of the scene considered
  size_t rgb_points = 0, labelled_points = 0;
};

// Row of the scene named `name`; DataError naming the scene table, the name and a few
// valid names otherwise (exit 2).
nuscenes::Index find_scene(const nuscenes::Database& db, const std::string& name);

// accumulate_location restricted to the sweeps of one scene (raster::accumulate_scenes).
raster::LocationLayers accumulate_scene(const nuscenes::Database& db, const std::string& scene,
                                        const raster::RasterOptions& options, int threads);

// The scene's cloud: accumulate_scene, then raster::colorize_scenes over its covered cells
// with the scene's key frames only (when options.camera.rgb or .semantic).
SceneCloud scene_cloud(const nuscenes::Database& db, const std::string& scene, const raster::RasterOptions& options,
                       int threads);

// Writes `points` as PCD v0.7 (fields x y z intensity rgb label; F4 F4 F4 F4 F4 U4; height
// 1, dense) through pcl::PCDWriter, to a temp file renamed over `out` (atomic). Throws
// IoError naming the file. Same points and format → same bytes.
void write_pcd(const std::vector<CloudPoint>& points, const std::filesystem::path& out, PcdFormat format);

struct ExportCloudOptions {
  std::filesystem::path dataroot;
  std::string version = "v1.0-mini";
  std::string scene;
  std::filesystem::path out;  // the .pcd file
  PcdFormat format = PcdFormat::kBinary;
  int threads = 0;  // 0 = all cores; the output does not depend on it
  raster::RasterOptions raster;
  void validate() const;  // ConfigError naming the bad field
};

// Loads the release, builds the scene's cloud and writes it. Returns the cloud (points
// included) for reporting.
SceneCloud export_cloud(const ExportCloudOptions& options);

}  // namespace nsg::pipeline

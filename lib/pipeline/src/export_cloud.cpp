#include "nsg/pipeline/export_cloud.h"

#include <algorithm>
#include <utility>

#include "nsg/core/error.h"
#include "nsg/core/strings.h"
#include "nsg/nuscenes/database.h"
#include "nsg/raster/color_layer.h"

namespace nsg::pipeline {

using nuscenes::Database;
using nuscenes::Index;

PcdFormat parse_pcd_format(const std::string& text) {
  if (text == "ascii") return PcdFormat::kAscii;
  if (text == "binary") return PcdFormat::kBinary;
  if (text == "binary_compressed") return PcdFormat::kBinaryCompressed;
  throw ConfigError("", "--encoding '" + text + "'", "one of binary, ascii, binary_compressed");
}

const char* pcd_format_name(PcdFormat format) {
  switch (format) {
    case PcdFormat::kAscii: return "ascii";
    case PcdFormat::kBinary: return "binary";
    case PcdFormat::kBinaryCompressed: return "binary_compressed";
  }
  return "?";
}

void ExportCloudOptions::validate() const {
  raster.validate();
  if (dataroot.empty()) throw ConfigError("", "--dataroot", "the release's dataroot folder");
  if (scene.empty()) throw ConfigError("", "--scene", "a scene name (scene.json 'name', e.g. scene-0061)");
  if (out.empty()) throw ConfigError("", "--out", "the .pcd file to write");
  if (threads < 0) throw ConfigError("", "--threads", "0 (all cores) or a positive count");
}

Index find_scene(const Database& db, const std::string& name) {
  for (Index s = 0; s < static_cast<Index>(db.scene.size()); ++s)
    if (db.scene[s].name == name) return s;
  constexpr size_t kShown = 5;
  std::vector<std::string> some;
  for (size_t s = 0; s < std::min(kShown, db.scene.size()); ++s) some.push_back(db.scene[static_cast<Index>(s)].name);
  std::string expected = "the name of a scene of the release (`nsgraph inspect scenes` lists them)";
  if (!some.empty())
    expected += " (" + join(some, ", ") + (db.scene.size() > kShown ? ", ..." : "") +
                strprintf("; %zu scenes)", db.scene.size());
  throw DataError(db.scene.file(), "scene '" + name + "'", expected);
}

namespace {

uint32_t pack_rgb(uint8_t r, uint8_t g, uint8_t b) {
  return 0xFF000000u | (static_cast<uint32_t>(r) << 16) | (static_cast<uint32_t>(g) << 8) | b;
}

}  // namespace

raster::LocationLayers accumulate_scene(const Database& db, const std::string& scene,
                                        const raster::RasterOptions& options, int threads) {
  return raster::accumulate_scenes(db, {find_scene(db, scene)}, options, threads);
}

SceneCloud scene_cloud(const Database& db, const std::string& scene, const raster::RasterOptions& options,
                       int threads) {
  const Index index = find_scene(db, scene);
  SceneCloud cloud;
  cloud.scene = scene;
  cloud.location = db.log[db.scene[index].log].location;
  const raster::LocationLayers layers = raster::accumulate_scenes(db, {index}, options, threads);
  cloud.sweeps = layers.stats.sweeps;
  const bool cameras = options.camera.rgb || options.camera.semantic;
  raster::ColorLayer color(layers.lidar.resolution_m());
  if (cameras) {
    color = raster::colorize_scenes(db, {index}, layers.lidar, {}, options.camera, threads);
    cloud.images = color.stats().images;
  }

  // Cells sorted by (row, col): the file's point order does not depend on block layout.
  struct Kept {
    raster::CellIndex cell;
    raster::LidarCell lidar;  // a copy: for_each's cells live only through the call (packed blocks)
  };
  std::vector<Kept> kept;
  kept.reserve(layers.stats.covered_cells);
  layers.lidar.cells().for_each([&](raster::CellIndex c, const raster::LidarCell& cell) {
    if (cell.has_data()) kept.push_back({c, cell});
  });
  std::sort(kept.begin(), kept.end(), [](const Kept& a, const Kept& b) {
    return a.cell.row != b.cell.row ? a.cell.row < b.cell.row : a.cell.col < b.cell.col;
  });
  cloud.points.reserve(kept.size());
  for (const Kept& k : kept) {
    CloudPoint p;
    p.x_m = k.lidar.x;
    p.y_m = k.lidar.y;
    p.z_m = k.lidar.z;
    p.intensity = static_cast<float>(k.lidar.intensity);
    if (const raster::ColorCell* c = cameras ? color.cells().find(k.cell) : nullptr) {
      if (c->flags & raster::kCoverageRgb) {
        p.rgb = pack_rgb(c->r, c->g, c->b);
        ++cloud.rgb_points;
      }
      if ((c->flags & raster::kCoverageSemantic) && c->semantic != 255) {
        p.label = c->semantic;
        ++cloud.labelled_points;
      }
    }
    cloud.points.push_back(p);
  }
  return cloud;
}

SceneCloud export_cloud(const ExportCloudOptions& given) {
  given.validate();
  ExportCloudOptions options = given;
  raster::resolve_semantic_source(options.raster.camera, options.dataroot, options.version);
  Database db = Database::load(options.dataroot, options.version);
  SceneCloud cloud = scene_cloud(db, options.scene, options.raster, options.threads);
  if (cloud.points.empty())  // PCL refuses an empty cloud; say why instead
    throw DataError(
        db.sample_data.file(), "scene '" + options.scene + "'",
        "LiDAR points in the scene's " + options.raster.lidar_channel + " sweeps (none survive the filters)");
  write_pcd(cloud.points, options.out, options.format);
  return cloud;
}

}  // namespace nsg::pipeline

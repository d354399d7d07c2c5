#include "nsg/io/tile_members.h"

#include "nsg/core/coverage_bits.h"

namespace nsg::io {

const std::vector<TileMember>& tile_members() {
  static const std::vector<TileMember> kMembers = {
      {"lidar", "lidar.tif", true, SampleType::kUInt8, 1, "intensity", 0.0, kCoverageLidar,
       "intensity of the lowest LiDAR point of the cell; 0 = no data"},
      {"rgb", "rgb.tif", true, SampleType::kUInt8, 3, "colour", 0.0, kCoverageRgb,
       "camera colour of that point; 0,0,0 = no data"},
      {"semantic", "semantic.tif", true, SampleType::kUInt8, 1, "class id", 255.0, kCoverageSemantic,
       "class id (samples/semantic-classes.json); 255 = no data"},
      {"vehicle", "vehicle.tif", true, SampleType::kFloat32, 1, "turns", -1.0, 0,
       "heading of the vehicle covering the cell, clockwise from north / 2π in [0, 1); -1 = none"},
      {"coverage", "coverage.tif", true, SampleType::kUInt8, 1, "bit flags", std::nullopt, 0,
       "bit flags: 1 LiDAR, 2 RGB, 4 semantics"},
      {"graph", "graph.json", false, SampleType::kUInt8, 0, "", std::nullopt, 0,
       "the directed lane graph clipped to the tile (tile-graph.schema.json)"},
      {"meta", "meta.json", false, SampleType::kUInt8, 0, "", std::nullopt, 0,
       "key, location, split, bounds, coverage fractions, counts, scenes (tile-meta.schema.json)"},
  };
  return kMembers;
}

std::vector<const TileMember*> raster_members() {
  std::vector<const TileMember*> out;
  for (const TileMember& m : tile_members())
    if (m.raster) out.push_back(&m);
  return out;
}

const TileMember* find_tile_member(std::string_view name) {
  for (const TileMember& m : tile_members())
    if (m.name == name || m.file == name) return &m;
  return nullptr;
}

const char* dtype_name(SampleType type) { return type == SampleType::kUInt8 ? "uint8" : "float32"; }

}  // namespace nsg::io

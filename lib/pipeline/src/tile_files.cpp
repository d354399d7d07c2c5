#include "nsg/pipeline/tile_files.h"

#include <cstring>

#include <nlohmann/json.hpp>

#include "nsg/io/raster.h"

namespace nsg::pipeline {

using nlohmann::ordered_json;

const std::vector<std::string>& tile_file_suffixes() {
  static const std::vector<std::string> kSuffixes = {"lidar.tif",    "rgb.tif",    "semantic.tif", "vehicle.tif",
                                                     "coverage.tif", "graph.json", "meta.json"};
  return kSuffixes;
}

namespace {

io::Raster raster_u8(const std::vector<uint8_t>& data, int size, int bands) {
  io::Raster r;
  r.width = r.height = size;
  r.bands = bands;
  r.type = io::SampleType::kUInt8;
  r.data = data;
  return r;
}

io::Raster raster_f32(const std::vector<float>& data, int size) {
  io::Raster r;
  r.width = r.height = size;
  r.type = io::SampleType::kFloat32;
  r.data.resize(data.size() * sizeof(float));
  std::memcpy(r.data.data(), data.data(), r.data.size());
  return r;
}

std::vector<uint8_t> bytes_of(const std::string& text) { return {text.begin(), text.end()}; }

std::string graph_json(const tiling::Tile& t) {
  ordered_json nodes = ordered_json::array();
  for (const graph::TileNode& n : t.graph.nodes)
    nodes.push_back({{"id", n.id}, {"u", n.u_px}, {"v", n.v_px}, {"x", n.x_m}, {"y", n.y_m}});
  ordered_json edges = ordered_json::array();
  for (const graph::TileEdge& e : t.graph.edges)
    edges.push_back({{"source", e.source}, {"target", e.target}, {"lane_token", e.lane_token}});
  const ordered_json doc = {{"schema_version", "1"}, {"key", t.key}, {"nodes", nodes}, {"edges", edges}};
  return doc.dump() + "\n";
}

std::string meta_json(const tiling::Tile& t, const std::vector<std::string>& scenes) {
  const ordered_json doc = {
      {"schema_version", "1"},
      {"key", t.key},
      {"location", t.location},
      {"split", t.crop.split},
      {"region", t.crop.region},
      {"bounds_m", {t.bounds.x_west_m, t.bounds.y_south_m, t.bounds.x_east_m, t.bounds.y_north_m}},
      {"resolution_m", t.resolution_m},
      {"size_px", t.rasters.size_px},
      {"coverage", {{"lidar", t.coverage_lidar}, {"rgb", t.coverage_rgb}, {"semantic", t.coverage_semantic}}},
      {"counts", {{"nodes", t.graph.nodes.size()}, {"edges", t.graph.edges.size()}, {"vehicle_px", t.vehicle_px}}},
      {"scenes", scenes}};
  return doc.dump(2) + "\n";
}

}  // namespace

std::vector<TileFile> encode_tile_files(const tiling::Tile& t, const TileFileOptions& options) {
  const int size = t.rasters.size_px;
  const io::GeoRef geo{t.location, t.bounds.x_west_m, t.bounds.y_north_m, t.resolution_m};
  const auto tif = [&](const io::Raster& r, std::optional<double> nodata) {
    io::GeoTiffOptions o;
    o.deflate_level = options.deflate_level;
    o.nodata = nodata;
    return io::encode_geotiff(r, geo, o);
  };
  std::vector<TileFile> files;
  files.push_back({t.key + ".lidar.tif", tif(raster_u8(t.rasters.lidar, size, 1), 0.0)});
  files.push_back({t.key + ".rgb.tif", tif(raster_u8(t.rasters.rgb, size, 3), 0.0)});
  files.push_back({t.key + ".semantic.tif", tif(raster_u8(t.rasters.semantic, size, 1), 255.0)});
  files.push_back({t.key + ".vehicle.tif", tif(raster_f32(t.rasters.vehicle, size), -1.0)});
  files.push_back({t.key + ".coverage.tif", tif(raster_u8(t.rasters.coverage, size, 1), std::nullopt)});
  files.push_back({t.key + ".graph.json", bytes_of(graph_json(t))});
  files.push_back({t.key + ".meta.json", bytes_of(meta_json(t, options.scenes))});
  return files;
}

}  // namespace nsg::pipeline

#include "nsg/pipeline/tile_files.h"

#include <cstring>

#include <nlohmann/json.hpp>

#include "nsg/core/error.h"
#include "nsg/io/raster.h"
#include "nsg/io/tile_members.h"

namespace nsg::pipeline {

using nlohmann::ordered_json;

const std::vector<std::string>& tile_file_suffixes() {
  static const std::vector<std::string> kSuffixes = [] {
    std::vector<std::string> out;
    for (const io::TileMember& m : io::tile_members()) out.push_back(m.file);
    return out;
  }();
  return kSuffixes;
}

io::Raster layer_raster(const tiling::TileRasters& r, const io::TileMember& member) {
  io::Raster out;
  out.width = r.width_px > 0 ? r.width_px : r.size_px;
  out.height = r.height_px > 0 ? r.height_px : r.size_px;
  out.bands = member.bands;
  out.type = member.dtype;
  if (member.name == "vehicle") {
    out.data.resize(r.vehicle.size() * sizeof(float));
    std::memcpy(out.data.data(), r.vehicle.data(), out.data.size());
  } else if (member.name == "lidar") {
    out.data = r.lidar;
  } else if (member.name == "rgb") {
    out.data = r.rgb;
  } else if (member.name == "semantic") {
    out.data = r.semantic;
  } else if (member.name == "coverage") {
    out.data = r.coverage;
  } else {
    throw InternalError("", member.file, "a raster member of io::tile_members()");
  }
  out.validate();
  return out;
}

namespace {

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
  const io::GeoRef geo{t.location, t.bounds.x_west_m, t.bounds.y_north_m, t.resolution_m};
  std::vector<TileFile> files;
  for (const io::TileMember& m : io::tile_members()) {
    std::vector<uint8_t> bytes;
    if (m.raster) {
      io::GeoTiffOptions o;
      o.deflate_level = options.deflate_level;
      o.nodata = m.nodata;
      bytes = io::encode_geotiff(layer_raster(t.rasters, m), geo, o);
    } else if (m.name == "graph") {
      bytes = bytes_of(graph_json(t));
    } else if (m.name == "meta") {
      bytes = bytes_of(meta_json(t, options.scenes));
    } else {
      throw InternalError("", m.file, "a member the tile writer knows");
    }
    files.push_back({t.key + "." + m.file, std::move(bytes)});
  }
  return files;
}

}  // namespace nsg::pipeline

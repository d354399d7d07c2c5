#include "nsg/pipeline/tile_files.h"

#include <cstring>

#include <nlohmann/json.hpp>

#include "nsg/core/error.h"
#include "nsg/io/raster.h"
#include "nsg/io/tile_graph.h"
#include "nsg/io/tile_members.h"
#include "nsg/io/tile_meta.h"

namespace nsg::pipeline {

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

// The tile's meta document (io/tile_meta.h writes it).
io::TileMeta tile_meta(const tiling::Tile& t, const TileFileOptions& options) {
  io::TileMeta m;
  m.key = t.key;
  m.location = t.location;
  m.split = t.crop.split;
  m.region = t.crop.region;
  m.bounds_m = {t.bounds.x_west_m, t.bounds.y_south_m, t.bounds.x_east_m, t.bounds.y_north_m};
  m.resolution_m = t.resolution_m;
  m.size_px = t.rasters.size_px;
  m.coverage_lidar = t.coverage_lidar;
  m.coverage_rgb = t.coverage_rgb;
  m.coverage_semantic = t.coverage_semantic;
  m.nodes = static_cast<int64_t>(t.graph.nodes.size());
  m.edges = static_cast<int64_t>(t.graph.edges.size());
  m.vehicle_px = t.vehicle_px;
  m.scenes = options.scenes;
  m.ladder = options.ladder;
  return m;
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
      bytes = bytes_of(io::tile_graph_text(t.key, t.graph, t.prior_graph ? &*t.prior_graph : nullptr));
    } else if (m.name == "meta") {
      bytes = bytes_of(io::tile_meta_text(tile_meta(t, options)));
    } else {
      throw InternalError("", m.file, "a member the tile writer knows");
    }
    files.push_back({t.key + "." + m.file, std::move(bytes)});
  }
  return files;
}

}  // namespace nsg::pipeline

#include "nsg/pipeline/stats.h"

#include <bitset>
#include <cmath>
#include <memory>

#include "nsg/core/error.h"
#include "nsg/core/strings.h"
#include "nsg/io/dataset.h"
#include "nsg/io/tile_graph.h"
#include "nsg/io/tile_meta.h"
#include "nsg/tiling/regions.h"

namespace nsg::pipeline {

namespace {

// Union of cell footprints in sparse 64 × 64 blocks (memory grows with the covered area).
class CellUnion {
 public:
  void add_rect(const std::string& location, int64_t col0, int64_t row0, int64_t size) {
    for (int64_t r = row0; r < row0 + size; ++r)
      for (int64_t c = col0; c < col0 + size; ++c) {
        auto& block = blocks_[{location, floor_div(c), floor_div(r)}];
        if (!block) block = std::make_unique<std::bitset<4096>>();
        const size_t bit = static_cast<size_t>((r - floor_div(r) * 64) * 64 + (c - floor_div(c) * 64));
        if (!block->test(bit)) {
          block->set(bit);
          ++cells_;
        }
      }
  }
  int64_t cells() const { return cells_; }

 private:
  static int64_t floor_div(int64_t a) { return a >= 0 ? a / 64 : -((-a + 63) / 64); }
  std::map<std::tuple<std::string, int64_t, int64_t>, std::unique_ptr<std::bitset<4096>>> blocks_;
  int64_t cells_ = 0;
};

}  // namespace

DatasetStats compute_stats(const std::filesystem::path& root) {
  const io::Dataset dataset = io::Dataset::open(root);
  DatasetStats stats;
  std::map<std::string, CellUnion> unions;
  double res = 0.2;
  // Every tile is the manifest's size and resolution: a tile's own size_px drives the
  // area loop, so it may not exceed what the dataset declares.
  const nlohmann::json& format = dataset.manifest().value("tile_format", nlohmann::json::object());
  const nlohmann::json want_size = format.value("size_px", nlohmann::json()),
                       want_res = format.value("resolution_m", nlohmann::json());
  dataset.for_each_tile("", [&](const io::DatasetTile& tile) {
    // Checked readers: a tile document is an outside file (io/tile_meta.h, io/tile_graph.h).
    const io::TileMeta meta = io::tile_meta_from_json(tile.json("meta.json"), tile.key + ".meta.json");
    const graph::TileGraph graph = io::tile_graph_from_json(tile.json("graph.json"), tile.key + ".graph.json");
    NSG_CHECK(!want_size.is_number_integer() || want_size.get<int64_t>() == meta.size_px, DataError,
              tile.key + ".meta.json", "/size_px", "the manifest's tile_format.size_px " + want_size.dump());
    NSG_CHECK(!want_res.is_number() || want_res.get<double>() == meta.resolution_m, DataError, tile.key + ".meta.json",
              "/resolution_m", "the manifest's tile_format.resolution_m " + want_res.dump());
    res = meta.resolution_m;
    const std::string& split = meta.split;
    const int64_t col0 = std::llround(meta.bounds_m[0] / res), row0 = std::llround(meta.bounds_m[1] / res);
    for (const std::string& s : {split, std::string("all")}) {
      SplitStats& st = stats.splits[s];
      ++st.tiles;
      unions[s].add_rect(meta.location, col0, row0, meta.size_px);
      st.lane_segments += static_cast<int64_t>(graph.edges.size());
      for (const graph::TileEdge& e : graph.edges) {
        const graph::TileNode &a = graph.nodes[e.source], &c = graph.nodes[e.target];
        st.lane_length_km += std::hypot(a.x_m - c.x_m, a.y_m - c.y_m) / 1000.0;
      }
      st.vehicle_px += meta.vehicle_px;
      st.mean_coverage_lidar += meta.coverage_lidar;
      st.mean_coverage_rgb += meta.coverage_rgb;
      st.mean_coverage_semantic += meta.coverage_semantic;
    }
    const io::Raster semantic = tile.raster("semantic.tif");
    std::bitset<256> present;
    for (uint8_t v : semantic.data) present.set(v);
    for (int c = 0; c < 255; ++c)
      if (present.test(c)) {
        stats.splits[split].semantic_classes.insert(c);
        stats.splits["all"].semantic_classes.insert(c);
      }
    return true;
  });
  for (auto& [name, st] : stats.splits) {
    st.labeled_area_km2 = static_cast<double>(unions[name].cells()) * res * res / 1e6;
    st.vehicle_area_km2 = static_cast<double>(st.vehicle_px) * res * res / 1e6;
    if (st.tiles > 0) {
      st.mean_coverage_lidar /= static_cast<double>(st.tiles);
      st.mean_coverage_rgb /= static_cast<double>(st.tiles);
      st.mean_coverage_semantic /= static_cast<double>(st.tiles);
    }
  }
  return stats;
}

nlohmann::ordered_json stats_json(const DatasetStats& stats) {
  nlohmann::ordered_json out = nlohmann::ordered_json::object();
  for (std::string_view name : {"train", "val", "test", "all"}) {
    auto it = stats.splits.find(std::string(name));
    if (it == stats.splits.end()) continue;
    const SplitStats& s = it->second;
    out[std::string(name)] = {
        {"tiles", s.tiles},
        {"labeled_area_km2", s.labeled_area_km2},
        {"lane_segments", s.lane_segments},
        {"lane_length_km", s.lane_length_km},
        {"vehicle_px", s.vehicle_px},
        {"vehicle_area_km2", s.vehicle_area_km2},
        {"semantic_classes", s.semantic_classes},
        {"mean_coverage",
         {{"lidar", s.mean_coverage_lidar}, {"rgb", s.mean_coverage_rgb}, {"semantic", s.mean_coverage_semantic}}}};
  }
  return out;
}

std::string stats_text(const DatasetStats& stats) {
  std::string out = strprintf("%-6s %7s %12s %10s %10s %12s %8s %24s\n", "split", "tiles", "area (km²)", "lane segs",
                              "lanes (km)", "vehicle km²", "classes", "coverage lidar/rgb/sem");
  for (std::string_view name : {"train", "val", "test", "all"}) {
    auto it = stats.splits.find(std::string(name));
    if (it == stats.splits.end()) continue;
    const SplitStats& s = it->second;
    out += strprintf("%-6s %7lld %12.4f %10lld %10.2f %12.5f %8zu %12.2f/%.2f/%.2f\n", std::string(name).c_str(),
                     static_cast<long long>(s.tiles), s.labeled_area_km2, static_cast<long long>(s.lane_segments),
                     s.lane_length_km, s.vehicle_area_km2, s.semantic_classes.size(), s.mean_coverage_lidar,
                     s.mean_coverage_rgb, s.mean_coverage_semantic);
  }
  return out;
}

}  // namespace nsg::pipeline

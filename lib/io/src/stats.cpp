#include "nsg/io/stats.h"

#include <algorithm>
#include <bitset>
#include <cmath>
#include <cstring>
#include <memory>
#include <utility>
#include <vector>

#include "nsg/core/error.h"
#include "nsg/core/progress.h"
#include "nsg/core/semantic_classes.h"
#include "nsg/core/strings.h"
#include "nsg/io/dataset.h"

namespace nsg::io {

namespace {

// Union of the tiles' pixel cells in sparse 64 × 64 blocks (memory grows with the covered
// area). World cell (col, row): col from x = 0 eastwards, row from y = 0 northwards, in
// pixels of the dataset's resolution; crops are cut on that grid.
class CellUnion {
 public:
  // Adds a tile's size × size cells with south-west cell (col0, row0) and returns, per tile
  // pixel (row 0 = north, row-major), whether this tile is the first to cover it: figures
  // counted only there count every place once however the crops overlap.
  std::vector<uint8_t> add_tile(const std::string& location, int64_t col0, int64_t row0, int64_t size) {
    std::vector<uint8_t> first(static_cast<size_t>(size * size), 0);
    for (int64_t py = 0; py < size; ++py)
      for (int64_t px = 0; px < size; ++px) {
        const int64_t c = col0 + px, r = row0 + size - 1 - py;
        auto& block = blocks_[{location, floor_div(c), floor_div(r)}];
        if (!block) block = std::make_unique<std::bitset<4096>>();
        const size_t bit = static_cast<size_t>((r - floor_div(r) * 64) * 64 + (c - floor_div(c) * 64));
        if (block->test(bit)) continue;
        block->set(bit);
        first[static_cast<size_t>(py * size + px)] = 1;
        ++cells_;
      }
    return first;
  }
  int64_t cells() const { return cells_; }

 private:
  static int64_t floor_div(int64_t a) { return a >= 0 ? a / 64 : -((-a + 63) / 64); }
  std::map<std::tuple<std::string, int64_t, int64_t>, std::unique_ptr<std::bitset<4096>>> blocks_;
  int64_t cells_ = 0;
};

// The tile pixel holding (u, v) (pixel centres at integers), clamped into the tile: a lane
// on the tile's border belongs to the tile (graph/clip.h).
size_t pixel_of(double u_px, double v_px, int64_t size) {
  const auto cell = [size](double t) {
    return std::clamp<int64_t>(static_cast<int64_t>(std::floor(t + 0.5)), 0, size - 1);
  };
  return static_cast<size_t>(cell(v_px) * size + cell(u_px));
}

// Metres of edge a→c lying in pixels where `counted` is set: the edge is cut exactly where
// it crosses a pixel border (u or v = k + 0.5) and each piece goes to the pixel of its middle.
double counted_length_m(const graph::TileNode& a, const graph::TileNode& c, const std::vector<uint8_t>& counted,
                        int64_t size) {
  const double length_m = std::hypot(c.x_m - a.x_m, c.y_m - a.y_m);
  std::vector<double> cuts{0.0, 1.0};
  for (const auto& [from, to] : {std::pair{a.u_px, c.u_px}, std::pair{a.v_px, c.v_px}}) {
    if (from == to) continue;
    const double lo = std::min(from, to), hi = std::max(from, to);
    for (double k = std::ceil(lo - 0.5) + 0.5; k < hi; k += 1.0)
      if (k > lo) cuts.push_back((k - from) / (to - from));
  }
  std::sort(cuts.begin(), cuts.end());
  double sum_m = 0.0;
  for (size_t i = 0; i + 1 < cuts.size(); ++i) {
    const double mid = 0.5 * (cuts[i] + cuts[i + 1]);
    if (counted[pixel_of(a.u_px + mid * (c.u_px - a.u_px), a.v_px + mid * (c.v_px - a.v_px), size)])
      sum_m += (cuts[i + 1] - cuts[i]) * length_m;
  }
  return sum_m;
}

// A semantic class id as its name (core/semantic_classes.h); an id beyond the table stays a number.
std::string class_label(int id) {
  return id < kSemanticClassCount ? std::string(kSemanticClasses[static_cast<size_t>(id)].name)
                                  : "class " + std::to_string(id);
}

}  // namespace

DatasetStats compute_stats(const std::filesystem::path& root, bool progress) {
  const Dataset dataset = Dataset::open(root);
  DatasetStats stats;
  std::map<std::string, CellUnion> unions;
  double res = 0.2;
  // Every tile is the manifest's size and resolution: a tile's own size_px drives the
  // area loop, so it may not exceed what the dataset declares.
  const TileFormat& format = dataset.manifest().tile_format;
  Progress bar("stats tiles", dataset.tile_count(""), progress);
  dataset.for_each_tile("", [&](const DatasetTile& tile) {
    // Checked readers: a tile document is an outside file (io/tile_meta.h, io/tile_graph.h).
    const TileMeta meta = tile.meta();
    const graph::TileGraph graph = tile.graph();
    NSG_CHECK(format.size_px == meta.size_px, DataError, tile.key + ".meta.json", "/size_px",
              "the manifest's tile_format.size_px " + std::to_string(format.size_px));
    NSG_CHECK(format.resolution_m == meta.resolution_m, DataError, tile.key + ".meta.json", "/resolution_m",
              "the manifest's tile_format.resolution_m " + nlohmann::json(format.resolution_m).dump());
    res = meta.resolution_m;
    const int64_t size = meta.size_px;
    const Raster vehicle = tile.raster("vehicle.tif");
    NSG_CHECK(vehicle.type == SampleType::kFloat32 && vehicle.width == size && vehicle.height == size, DataError,
              tile.key + ".vehicle.tif", "raster", "a float32 raster of the tile's size");
    const int64_t col0 = std::llround(meta.bounds_m[0] / res), row0 = std::llround(meta.bounds_m[1] / res);
    for (const std::string& s : {meta.split, std::string("all")}) {
      SplitStats& st = stats.splits[s];
      ++st.tiles;
      const std::vector<uint8_t> first = unions[s].add_tile(meta.location, col0, row0, size);
      for (const graph::TileEdge& e : graph.edges) {
        const graph::TileNode &a = graph.nodes[e.source], &c = graph.nodes[e.target];
        st.lane_length_km += counted_length_m(a, c, first, size) / 1000.0;
        // A segment cut by several crops counts once, in the tile first covering its middle.
        if (first[pixel_of(0.5 * (a.u_px + c.u_px), 0.5 * (a.v_px + c.v_px), size)]) ++st.lane_segments;
      }
      for (size_t i = 0; i < first.size(); ++i) {
        if (!first[i]) continue;
        float heading;  // -1 = no vehicle, else the heading as a turn fraction in [0, 1)
        std::memcpy(&heading, vehicle.data.data() + 4 * i, 4);
        if (heading >= 0.0f && heading < 1.0f) ++st.vehicle_px;
      }
      st.mean_coverage_lidar += meta.coverage_lidar;
      st.mean_coverage_rgb += meta.coverage_rgb;
      st.mean_coverage_semantic += meta.coverage_semantic;
    }
    const Raster semantic = tile.raster("semantic.tif");
    std::bitset<256> present;
    for (uint8_t v : semantic.data) present.set(v);
    for (int c = 0; c < 255; ++c)
      if (present.test(c)) {
        stats.splits[meta.split].semantic_classes.insert(c);
        stats.splits["all"].semantic_classes.insert(c);
      }
    bar.advance();
    return true;
  });
  bar.finish();
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

namespace {
std::vector<std::string> class_names_of(const std::set<int>& ids) {
  std::vector<std::string> names;
  for (int id : ids) names.push_back(class_label(id));
  return names;
}
}  // namespace

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
        {"semantic_classes", class_names_of(s.semantic_classes)},
        {"mean_coverage",
         {{"lidar", s.mean_coverage_lidar}, {"rgb", s.mean_coverage_rgb}, {"semantic", s.mean_coverage_semantic}}}};
  }
  return out;
}

std::string stats_text(const DatasetStats& stats) {
  std::string out = strprintf("%-6s %7s %12s %10s %10s %12s %8s %24s\n", "split", "tiles", "area (km²)", "lane segs",
                              "lanes (km)", "vehicles km²", "classes", "coverage lidar/rgb/sem");
  for (std::string_view name : {"train", "val", "test", "all"}) {
    auto it = stats.splits.find(std::string(name));
    if (it == stats.splits.end()) continue;
    const SplitStats& s = it->second;
    out += strprintf("%-6s %7lld %12.4f %10lld %10.2f %12.5f %8zu %12.2f/%.2f/%.2f\n", std::string(name).c_str(),
                     static_cast<long long>(s.tiles), s.labeled_area_km2, static_cast<long long>(s.lane_segments),
                     s.lane_length_km, s.vehicle_area_km2, s.semantic_classes.size(), s.mean_coverage_lidar,
                     s.mean_coverage_rgb, s.mean_coverage_semantic);
  }
  out +=
      "area, lanes and vehicles are measured on the union of a split's tiles (overlapping crops count once);\n"
      "coverage is the mean over its tiles";
  if (auto it = stats.splits.find("all"); it != stats.splits.end() && !it->second.semantic_classes.empty()) {
    out += "; classes present:";
    for (const std::string& n : class_names_of(it->second.semantic_classes)) out += " " + n;
  }
  return out + "\n";
}

}  // namespace nsg::io

#include "nsg/tiling/regions.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>

#include "nsg/core/error.h"
#include "nsg/core/options.h"
#include "nsg/core/rng.h"
#include "nsg/raster/lidar_layer.h"
#include "nsg/tiling/crops.h"

namespace nsg::tiling {

bool is_split_name(std::string_view name) {
  return std::find(kSplitNames.begin(), kSplitNames.end(), name) != kSplitNames.end();
}

int split_index(std::string_view split) {
  for (size_t i = 0; i < kSplitNames.size(); ++i)
    if (kSplitNames[i] == split) return static_cast<int>(i);
  return -1;
}

bool RectM::contains(const RectM& inner) const {
  return inner.x_west_m >= x_west_m && inner.x_east_m <= x_east_m && inner.y_south_m >= y_south_m &&
         inner.y_north_m <= y_north_m;
}

double RectM::distance_to(const RectM& o) const {
  const double dx = std::max({0.0, o.x_west_m - x_east_m, x_west_m - o.x_east_m});
  const double dy = std::max({0.0, o.y_south_m - y_north_m, y_south_m - o.y_north_m});
  return std::hypot(dx, dy);
}

const options::Table<SplitOptions>& split_option_table() {
  static const options::Table<SplitOptions> table = [] {
    options::Table<SplitRatios> ratios;
    for (auto [name, field] : {std::pair{"train", &SplitRatios::train}, std::pair{"val", &SplitRatios::val},
                               std::pair{"test", &SplitRatios::test}})
      ratios.number(std::string("splits.ratios.") + name, field)
          .range(options::between(0, 1))
          .help(std::string("Automatic blocks: share of the blocks assigned to ") + name + " (the three sum to 1)");
    options::Table<SplitOptions> t;
    t.include(&SplitOptions::ratios, ratios);
    t.number("splits.buffer_m", &SplitOptions::buffer_m)
        .unit("m")
        .range(options::at_least(0))
        .help("Gap between regions of different splits (at least one crop)");
    t.number("splits.block_size_m", &SplitOptions::block_size_m)
        .unit("m")
        .range(options::at_least(0))
        .help("Automatic blocks: edge length (0 = from the covered extent; else at least one crop plus the buffer)");
    t.number("splits.min_block_coverage", &SplitOptions::min_block_coverage)
        .range(options::between(0, 1))
        .help("Automatic blocks: a block takes part only when at least this fraction of its cells hold LiDAR");
    return t;
  }();
  return table;
}

void SplitOptions::validate(double crop_size_m) const {
  split_option_table().check(*this);
  check_relations(crop_size_m);
}

void SplitOptions::check_relations(double crop_size_m) const {
  const auto bad = [](const std::string& field, const std::string& expected) {
    throw ConfigError("", "splits." + field, expected);
  };
  if (!(buffer_m >= crop_size_m))
    bad("buffer_m", "a buffer of at least one crop (" + std::to_string(crop_size_m) + " m)");
  if (!(block_size_m == 0.0 || block_size_m >= crop_size_m + buffer_m))
    bad("block_size_m", "0 (automatic) or at least one crop plus the buffer");
  if (std::abs(ratios.train + ratios.val + ratios.test - 1.0) > 1e-6) bad("ratios", "train + val + test = 1");
  std::set<std::string> names;
  for (const Region& r : regions) {
    if (r.name.empty() || r.name.find('.') != std::string::npos)
      bad("regions", "region names without dots ('" + r.name + "')");
    if (!names.insert(r.name).second) bad("regions", "unique region names ('" + r.name + "' repeats)");
    if (!is_split_name(r.split)) bad("regions." + r.name + ".split", "train, val or test (got '" + r.split + "')");
    if (!r.bounds.valid())
      bad("regions." + r.name + ".bounds_m", "[x_west, y_south, x_east, y_north] with west < east, south < north");
    if (r.bounds.width_m() < crop_size_m || r.bounds.height_m() < crop_size_m)
      bad("regions." + r.name + ".bounds_m", "a region holding at least one crop");
  }
  for (size_t i = 0; i < regions.size(); ++i)
    for (size_t j = i + 1; j < regions.size(); ++j)
      if (regions[i].split != regions[j].split && regions[i].bounds.distance_to(regions[j].bounds) < buffer_m - 1e-6)
        bad("regions", "regions of different splits at least buffer_m apart ('" + regions[i].name + "' and '" +
                           regions[j].name + "' are closer)");
}

CellWindow covered_window(const raster::LidarLayer& lidar) {
  CellWindow e{std::numeric_limits<int64_t>::max(), std::numeric_limits<int64_t>::max(),
               std::numeric_limits<int64_t>::min(), std::numeric_limits<int64_t>::min()};
  lidar.cells().for_each([&](raster::CellIndex c, const raster::LidarCell& cell) {
    if (!cell.has_data()) return;
    e.col0 = std::min(e.col0, c.col);
    e.row0 = std::min(e.row0, c.row);
    e.col1 = std::max(e.col1, c.col + 1);
    e.row1 = std::max(e.row1, c.row + 1);
  });
  return e.empty() ? CellWindow{} : e;
}

double min_split_gap_m(const std::vector<Region>& regions) {
  double gap = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < regions.size(); ++i)
    for (size_t j = i + 1; j < regions.size(); ++j)
      if (regions[i].split != regions[j].split) gap = std::min(gap, regions[i].bounds.distance_to(regions[j].bounds));
  return gap;
}

namespace {

// Automatic block edge: about four blocks across the longer side of the covered extent
// (so even a small release gets a train and a test block), never less than one crop
// plus the buffer, rounded up to whole cells.
double auto_block_size_m(double extent_w_m, double extent_h_m, double crop_size_m, double buffer_m) {
  const double from_extent = std::max(extent_w_m, extent_h_m) / 4.0;
  return std::max(from_extent, crop_size_m + buffer_m);
}

int split_rank(const std::string& split) {  // who keeps the ground between two splits
  return split == "test" ? 2 : split == "val" ? 1 : 0;
}

struct Block {
  int64_t bx = 0, by = 0;
  RectM bounds;
  std::string split;
};

// The grid of square blocks over the covered window, in whole cells.
struct BlockGrid {
  double x0_m = 0, y0_m = 0, block_m = 0;  // south-west corner, edge
  int64_t nx = 0, ny = 0, block_cells = 0;
};

BlockGrid block_grid(const CellWindow& e, double res, const SplitOptions& options, double crop_size_m) {
  BlockGrid g;
  g.x0_m = static_cast<double>(e.col0) * res, g.y0_m = static_cast<double>(e.row0) * res;
  const double w = static_cast<double>(e.col1 - e.col0) * res, h = static_cast<double>(e.row1 - e.row0) * res;
  double block_m =
      options.block_size_m > 0 ? options.block_size_m : auto_block_size_m(w, h, crop_size_m, options.buffer_m);
  block_m = std::ceil(block_m / res - 1e-9) * res;
  g.block_m = block_m;
  g.nx = static_cast<int64_t>(std::ceil(w / block_m - 1e-9));
  g.ny = static_cast<int64_t>(std::ceil(h / block_m - 1e-9));
  g.block_cells = static_cast<int64_t>(std::llround(block_m / res));
  return g;
}

// The blocks with enough coverage, row by row; counts the others in `st`.
std::vector<Block> covered_blocks(const raster::LidarLayer& lidar, const BlockGrid& g, const SplitOptions& options,
                                  RegionStats& st) {
  const double x0 = g.x0_m, y0 = g.y0_m, block_m = g.block_m;
  std::vector<Block> blocks;
  for (int64_t by = 0; by < g.ny; ++by)
    for (int64_t bx = 0; bx < g.nx; ++bx) {
      Block b{bx, by, {x0 + bx * block_m, y0 + by * block_m, x0 + (bx + 1) * block_m, y0 + (by + 1) * block_m}, ""};
      const double cells = static_cast<double>(g.block_cells * g.block_cells);
      if (static_cast<double>(covered_cells_in(lidar, b.bounds)) >= options.min_block_coverage * cells)
        blocks.push_back(b);
      else ++st.blocks_low_coverage;
    }
  return blocks;
}

// Splits by the ratios: the blocks ordered by a seeded hash of their grid position take
// test, then val, then train.
void assign_splits(std::vector<Block>& blocks, const SplitOptions& options, uint64_t seed, RegionStats& st) {
  const auto rank = [&](const Block& b) {
    return mix64(seed ^ mix64(static_cast<uint64_t>(b.bx) * 0x9E3779B97F4A7C15ull + static_cast<uint64_t>(b.by)));
  };
  std::vector<size_t> order(blocks.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    const uint64_t ra = rank(blocks[a]), rb = rank(blocks[b]);
    return ra != rb ? ra < rb : a < b;
  });
  const double n = static_cast<double>(blocks.size());
  size_t n_test = static_cast<size_t>(std::llround(n * options.ratios.test));
  if (n_test == 0 && options.ratios.test > 0 && blocks.size() >= 2) n_test = 1;
  size_t n_val = static_cast<size_t>(std::llround(n * options.ratios.val));
  if (n_test + n_val > blocks.size()) n_val = blocks.size() - n_test;
  for (size_t k = 0; k < order.size(); ++k) {
    blocks[order[k]].split = k < n_test ? "test" : k < n_test + n_val ? "val" : "train";
    ++st.blocks_assigned[static_cast<size_t>(split_index(blocks[order[k]].split))];
  }
}

using BlockAt = std::map<std::pair<int64_t, int64_t>, const Block*>;

// A block's bounds less `buffer_m` on each side that faces (edge or corner) a block of a
// split ranked higher; equal ranks never meet across different splits.
RectM buffered_bounds(const Block& b, const BlockAt& at, double buffer_m) {
  RectM r = b.bounds;
  // Edge neighbours first; a corner neighbour then costs only the west/east side, and
  // only if the edge cuts did not already open the gap.
  for (const bool corners : {false, true})
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        if ((dx != 0 && dy != 0) != corners || (dx == 0 && dy == 0)) continue;
        auto it = at.find({b.bx + dx, b.by + dy});
        if (it == at.end() || split_rank(it->second->split) <= split_rank(b.split)) continue;
        if (r.distance_to(it->second->bounds) >= buffer_m) continue;
        if (dx < 0) r.x_west_m = b.bounds.x_west_m + buffer_m;
        if (dx > 0) r.x_east_m = b.bounds.x_east_m - buffer_m;
        if (dy < 0 && !corners) r.y_south_m = b.bounds.y_south_m + buffer_m;
        if (dy > 0 && !corners) r.y_north_m = b.bounds.y_north_m - buffer_m;
      }
  return r;
}

// One region per block that still holds a crop after its buffers, named by split and grid
// position; counts the others in `st`.
std::vector<Region> buffered_regions(const std::vector<Block>& blocks, const SplitOptions& options, double crop_size_m,
                                     RegionStats& st) {
  BlockAt at;
  for (const Block& b : blocks) at[{b.bx, b.by}] = &b;
  std::vector<Region> regions;
  for (const Block& b : blocks) {
    const RectM r = buffered_bounds(b, at, options.buffer_m);
    if (r.width_m() < crop_size_m || r.height_m() < crop_size_m) {
      ++st.blocks_too_small[static_cast<size_t>(split_index(b.split))];
      continue;
    }
    char name[64];
    std::snprintf(name, sizeof name, "%s-%02lld-%02lld", b.split.c_str(), static_cast<long long>(b.bx),
                  static_cast<long long>(b.by));
    regions.push_back({name, b.split, r});
  }
  return regions;
}

}  // namespace

std::vector<Region> plan_regions(const raster::LidarLayer& lidar, const SplitOptions& options, double crop_size_m,
                                 uint64_t seed, RegionStats* stats) {
  // `options` were checked where they were read (the config reader, or validate()).
  RegionStats local;
  RegionStats& st = stats != nullptr ? *stats : local;
  st = {};
  if (!options.regions.empty()) {
    st.explicit_regions = true;
    return options.regions;
  }
  const CellWindow e = covered_window(lidar);
  if (e.empty()) {
    st.no_lidar = true;
    return {};
  }
  const BlockGrid grid = block_grid(e, lidar.resolution_m(), options, crop_size_m);
  st.block_size_m = grid.block_m;
  st.blocks = grid.nx * grid.ny;
  std::vector<Block> blocks = covered_blocks(lidar, grid, options, st);
  assign_splits(blocks, options, seed, st);
  return buffered_regions(blocks, options, crop_size_m, st);
}

}  // namespace nsg::tiling

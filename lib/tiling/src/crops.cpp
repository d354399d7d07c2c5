#include "nsg/tiling/crops.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "nsg/core/error.h"
#include "nsg/core/options.h"
#include "nsg/core/rng.h"
#include "nsg/raster/lidar_layer.h"

namespace nsg::tiling {

const options::Table<CropOptions>& crop_option_table() {
  static const options::Table<CropOptions> table = [] {
    options::Table<CropOptions> t;
    const std::vector<std::pair<std::string, Placement>> placements = {{"random", Placement::kRandom},
                                                                       {"grid", Placement::kGrid}};
    t.integer("crops.size_px", &CropOptions::size_px)
        .unit("px")
        .range(options::between(8, 4096))
        .help("Edge of a square crop (tile)");
    t.number("crops.min_lidar_coverage", &CropOptions::min_lidar_coverage)
        .range(options::between(0, 1))
        .help("Keep a crop only when at least this fraction of its cells hold LiDAR");
    t.choice("crops.placement.train", &CropOptions::train, placements).help("Where train crops go");
    t.choice("crops.placement.val", &CropOptions::val, placements).help("Where val crops go");
    t.choice("crops.placement.test", &CropOptions::test, placements).help("Where test crops go");
    t.number("crops.random_per_km2", &CropOptions::random_per_km2)
        .unit("1/km²")
        .range(options::between(0, 1e6))
        .help("Random placement: crops wanted per km² of a region's LiDAR-covered area");
    t.integer("crops.random_total", &CropOptions::random_total)
        .range(options::between(0, 100000))
        .help(
            "Random placement: crops wanted per split in total, spread by covered area (0 = use random_per_km2; "
            "at most 100 000: the whole of nuScenes yields a few thousand)");
    t.integer("crops.attempts_per_crop", &CropOptions::attempts_per_crop)
        .range(options::at_least(1))
        .help("Random placement: draws per wanted crop before giving up");
    return t;
  }();
  return table;
}

void CropOptions::validate() const { crop_option_table().check(*this); }

RectM Crop::bounds(double resolution_m, int size_px) const {
  return {static_cast<double>(col0) * resolution_m, static_cast<double>(row0) * resolution_m,
          static_cast<double>(col0 + size_px) * resolution_m, static_cast<double>(row0 + size_px) * resolution_m};
}

namespace {

using raster::CellIndex;
using raster::kBlockCells;

int64_t floor_div(int64_t a, int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

// Covered cells of the half-open cell window [col0, col1) × [row0, row1), block by block.
int64_t covered_cells_window(const raster::LidarLayer& lidar, int64_t col0, int64_t row0, int64_t col1, int64_t row1) {
  // The window's part of block b along one axis, block-local.
  const auto local = [](int64_t v, int64_t b) {
    return static_cast<int>(std::clamp<int64_t>(v - b * kBlockCells, 0, kBlockCells));
  };
  int64_t n = 0;
  for (int64_t by = floor_div(row0, kBlockCells); by * kBlockCells < row1; ++by)
    for (int64_t bx = floor_div(col0, kBlockCells); bx * kBlockCells < col1; ++bx)
      n += static_cast<int64_t>(
          lidar.cells().count_with_data(bx, by, local(col0, bx), local(col1, bx), local(row0, by), local(row1, by)));
  return n;
}

// Cells whose centre lies in [lo, hi): first = ceil(lo/res − 0.5), end = ceil(hi/res − 0.5).
int64_t first_cell(double lo_m, double res) { return static_cast<int64_t>(std::ceil(lo_m / res - 0.5)); }

struct CellSpan {
  int64_t col0, row0, col1, row1;
};
CellSpan cells_of(const RectM& r, double res) {
  return {first_cell(r.x_west_m, res), first_cell(r.y_south_m, res), first_cell(r.x_east_m, res),
          first_cell(r.y_north_m, res)};
}

// Crops wholly inside the region: south-west corners in [lo, hi] (cells).
struct CornerRange {
  int64_t col_lo, col_hi, row_lo, row_hi;
  bool empty() const { return col_hi < col_lo || row_hi < row_lo; }
};
CornerRange corner_range(const RectM& r, double res, int size_px) {
  return {static_cast<int64_t>(std::ceil(r.x_west_m / res - 1e-9)),
          static_cast<int64_t>(std::floor(r.x_east_m / res + 1e-9)) - size_px,
          static_cast<int64_t>(std::ceil(r.y_south_m / res - 1e-9)),
          static_cast<int64_t>(std::floor(r.y_north_m / res + 1e-9)) - size_px};
}

// Tests one candidate window: kept (appended to `out`) or counted as below the threshold.
void consider(const raster::LidarLayer& lidar, const Region& region, int64_t col, int64_t row, const CropOptions& o,
              SplitCropStats& st, std::vector<Crop>& out) {
  const double cov = window_coverage(lidar, col, row, o.size_px);
  ++st.windows;
  if (cov < o.min_lidar_coverage || cov <= 0.0) {
    ++st.below_coverage;
    st.best_rejected_coverage = std::max(st.best_rejected_coverage, cov);
    return;
  }
  out.push_back({region.name, region.split, col, row, cov});
  ++st.kept;
}

void grid_crops(const raster::LidarLayer& lidar, const Region& region, const CropOptions& o, SplitCropStats& st,
                std::vector<Crop>& out) {
  const CornerRange range = corner_range(region.bounds, lidar.resolution_m(), o.size_px);
  if (range.empty()) {
    ++st.regions_no_room;
    return;
  }
  for (int64_t row = range.row_lo; row <= range.row_hi; row += o.size_px)
    for (int64_t col = range.col_lo; col <= range.col_hi; col += o.size_px)
      consider(lidar, region, col, row, o, st, out);
}

void random_crops(const raster::LidarLayer& lidar, const Region& region, int64_t wanted, const CropOptions& o,
                  uint64_t seed, SplitCropStats& st, std::vector<Crop>& out) {
  const CornerRange range = corner_range(region.bounds, lidar.resolution_m(), o.size_px);
  if (range.empty()) {
    ++st.regions_no_room;
    return;
  }
  if (wanted <= 0) {
    ++st.regions_none_wanted;
    return;
  }
  st.wanted += wanted;
  Rng rng(seed, hash_string(region.name.data(), region.name.size()));
  const int64_t kept_before = st.kept;
  for (int64_t attempt = 0; attempt < wanted * o.attempts_per_crop && st.kept - kept_before < wanted; ++attempt) {
    const int64_t col = rng.uniform_int(range.col_lo, range.col_hi);
    const int64_t row = rng.uniform_int(range.row_lo, range.row_hi);
    consider(lidar, region, col, row, o, st, out);
  }
}

Placement placement_of(const CropOptions& o, const std::string& split) {
  return split == "train" ? o.train : split == "val" ? o.val : o.test;
}

}  // namespace

double window_coverage(const raster::LidarLayer& lidar, int64_t col0, int64_t row0, int size_px) {
  const int64_t n = covered_cells_window(lidar, col0, row0, col0 + size_px, row0 + size_px);
  return static_cast<double>(n) / (static_cast<double>(size_px) * size_px);
}

int64_t covered_cells_in(const raster::LidarLayer& lidar, const RectM& rect) {
  const CellSpan s = cells_of(rect, lidar.resolution_m());
  return covered_cells_window(lidar, s.col0, s.row0, s.col1, s.row1);
}

std::vector<Crop> plan_crops(const raster::LidarLayer& lidar, const std::vector<Region>& regions,
                             const CropOptions& options, uint64_t seed, CropStats* stats) {
  // `options` were checked where they were read (the config reader, or validate()).
  CropStats local;
  CropStats& st = stats != nullptr ? *stats : local;
  st = {};
  const double cell_km2 = lidar.resolution_m() * lidar.resolution_m() * 1e-6;
  // Covered area per region, and per split (to spread a total over the split's regions).
  std::vector<double> covered_km2(regions.size());
  std::map<std::string, double> split_km2;
  for (size_t i = 0; i < regions.size(); ++i) {
    covered_km2[i] = static_cast<double>(covered_cells_in(lidar, regions[i].bounds)) * cell_km2;
    split_km2[regions[i].split] += covered_km2[i];
  }
  // Regions are validated to carry a split name (explicit) or get one (automatic).
  const auto split_stats = [&](const std::string& split) -> SplitCropStats& {
    const int k = split_index(split);
    if (k < 0) throw InternalError("", "region split", "train, val or test (got '" + split + "')");
    return st.splits[static_cast<size_t>(k)];
  };
  std::vector<Crop> crops;
  for (size_t i = 0; i < regions.size(); ++i) {
    const Region& region = regions[i];
    SplitCropStats& sst = split_stats(region.split);
    ++sst.regions;
    sst.covered_km2 += covered_km2[i];
    if (placement_of(options, region.split) == Placement::kGrid) {
      grid_crops(lidar, region, options, sst, crops);
      continue;
    }
    const double share = split_km2[region.split] > 0 ? covered_km2[i] / split_km2[region.split] : 0.0;
    const double wanted = options.random_total > 0 ? static_cast<double>(options.random_total) * share
                                                   : options.random_per_km2 * covered_km2[i];
    random_crops(lidar, region, static_cast<int64_t>(std::llround(wanted)), options, seed, sst, crops);
  }
  return crops;
}

}  // namespace nsg::tiling

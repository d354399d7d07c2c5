#include "nsg/raster/lidar_layer.h"

#include <algorithm>
#include <cmath>

#include "nsg/core/error.h"

namespace nsg::raster {

void LidarOptions::validate() const {
  if (!(resolution_m > 0.0)) throw ConfigError("", "lidar.resolution_m", "expected > 0 m");
  if (!(roof_half_size_m >= 0.0)) throw ConfigError("", "lidar.roof_half_size_m", "expected ≥ 0 m");
  if (!(max_range_m > 0.0)) throw ConfigError("", "lidar.max_range_m", "expected > 0 m");
}

std::vector<int32_t> select_sweep_points(const float* points, size_t count, size_t stride,
                                         const LidarOptions& options) {
  std::vector<int32_t> kept;
  kept.reserve(count);
  const double roof = options.roof_half_size_m;
  const double range2 = options.max_range_m * options.max_range_m;
  for (size_t i = 0; i < count; ++i) {
    const double x = points[i * stride], y = points[i * stride + 1];
    if (std::abs(x) < roof && std::abs(y) < roof) continue;  // a square, like remove_close
    if (x * x + y * y > range2) continue;
    kept.push_back(static_cast<int32_t>(i));
  }
  return kept;
}

void LidarLayer::offer(CellIndex c, const LidarCell& cell) {
  LidarCell& current = cells_.at(c);
  if (!current.has_data() || cell.lower_than(current)) current = cell;
}

namespace {

// floor(x / res) exactly as cell_of computes it, but with a multiplication by 1/res (a
// division per coordinate was a third of the binning time): the product differs from the
// quotient by a few ulps, so only a value within 1e-6 of a cell border is re-checked with
// the division. Clamped so a corrupt coordinate cannot overflow the cast.
inline int64_t floor_cell(double x_m, double resolution_m, double inv_resolution) {
  const double q = std::clamp(x_m * inv_resolution, -1e15, 1e15);
  auto i = static_cast<int64_t>(q);
  i -= static_cast<double>(i) > q;
  const double frac = q - static_cast<double>(i);
  if (frac < 1e-6 || frac > 1.0 - 1e-6) [[unlikely]] {
    const double exact = std::clamp(x_m / resolution_m, -1e15, 1e15);
    i = static_cast<int64_t>(exact);
    i -= static_cast<double>(i) > exact;
  }
  return i;
}

// A point binned to a cell: the block slot of the sweep's local block table and the
// cell's offset in its block.
struct Binned {
  uint32_t slot;
  uint32_t offset;
};

// Per-thread scratch of add_points, reused across sweeps (no allocation per sweep).
struct BinScratch {
  std::vector<int64_t> cols, rows;
  std::vector<Binned> binned;
  std::vector<uint32_t> bucket_start, bucket_fill, order;
};
thread_local BinScratch scratch;

static_assert(kBlockCells == 64, "add_points bins with shifts and masks of 64");

// Largest local block table (blocks² of pointers) before falling back to per-point
// lookups; a 60 m sweep spans about 10 × 10 blocks.
constexpr int64_t kMaxLocalBlocks = 64 * 64;

}  // namespace

void LidarLayer::add_points(const float* xyzi, size_t count, size_t stride, int32_t sweep_id,
                            const int32_t* point_ids) {
  if (count == 0) return;
  std::vector<int64_t>& cols = scratch.cols;
  std::vector<int64_t>& rows = scratch.rows;
  std::vector<Binned>& binned = scratch.binned;
  std::vector<uint32_t>& bucket_start = scratch.bucket_start;
  std::vector<uint32_t>& order = scratch.order;
  const auto make_cell = [&](size_t i) {
    const float* p = xyzi + i * stride;
    LidarCell cell;
    cell.x = p[0];
    cell.y = p[1];
    cell.z = p[2];
    cell.intensity = static_cast<uint8_t>(std::clamp(std::lround(p[3]), 0L, 255L));
    cell.sweep = sweep_id;
    cell.point = point_ids ? point_ids[i] : static_cast<int32_t>(i);
    return cell;
  };
  // Pass 1: cells and the sweep's block extent.
  cols.resize(count);
  rows.resize(count);
  int64_t c_min = INT64_MAX, c_max = INT64_MIN, r_min = INT64_MAX, r_max = INT64_MIN;
  const double inv_res = 1.0 / resolution_m_;
  for (size_t i = 0; i < count; ++i) {
    const float* p = xyzi + i * stride;
    cols[i] = floor_cell(p[0], resolution_m_, inv_res);
    rows[i] = floor_cell(p[1], resolution_m_, inv_res);
    c_min = std::min(c_min, cols[i]), c_max = std::max(c_max, cols[i]);
    r_min = std::min(r_min, rows[i]), r_max = std::max(r_max, rows[i]);
  }
  const int64_t bx0 = SparseGrid<LidarCell>::floor_div(c_min), by0 = SparseGrid<LidarCell>::floor_div(r_min);
  const int64_t bw = SparseGrid<LidarCell>::floor_div(c_max) - bx0 + 1;
  const int64_t bh = SparseGrid<LidarCell>::floor_div(r_max) - by0 + 1;
  if (bw > kMaxLocalBlocks || bh > kMaxLocalBlocks || bw * bh > kMaxLocalBlocks) {  // scattered far and wide: no local table
    SparseGrid<LidarCell>::Cursor cursor;
    for (size_t i = 0; i < count; ++i) {
      LidarCell& current = cells_.at({cols[i], rows[i]}, cursor);
      const LidarCell cell = make_cell(i);
      if (!current.has_data() || cell.lower_than(current)) current = cell;
    }
    return;
  }
  // Pass 2: bucket the points by block (counting sort), so each block's cells are
  // updated together while they sit in cache instead of scattered over the whole sweep.
  const auto nblocks = static_cast<size_t>(bw * bh);
  bucket_start.assign(nblocks + 1, 0);
  binned.resize(count);
  for (size_t i = 0; i < count; ++i) {
    const int64_t bx = cols[i] >> 6, by = rows[i] >> 6;  // floor division by kBlockCells = 64
    const auto slot = static_cast<uint32_t>((by - by0) * bw + (bx - bx0));
    binned[i] = {slot, static_cast<uint32_t>(((rows[i] & 63) << 6) | (cols[i] & 63))};
    ++bucket_start[slot + 1];
  }
  for (size_t b = 0; b < nblocks; ++b) bucket_start[b + 1] += bucket_start[b];
  order.resize(count);
  {
    std::vector<uint32_t>& fill = scratch.bucket_fill;
    fill.assign(bucket_start.begin(), bucket_start.end() - 1);
    for (size_t i = 0; i < count; ++i) order[fill[binned[i].slot]++] = static_cast<uint32_t>(i);
  }
  // Pass 3: one block lookup per touched block, then plain array updates.
  for (size_t b = 0; b < nblocks; ++b) {
    const uint32_t begin = bucket_start[b], end = bucket_start[b + 1];
    if (begin == end) continue;
    const int64_t bx = bx0 + static_cast<int64_t>(b) % bw, by = by0 + static_cast<int64_t>(b) / bw;
    LidarCell* block = cells_.block_data(bx, by);
    for (uint32_t k = begin; k < end; ++k) {
      const uint32_t i = order[k];
      LidarCell& current = block[binned[i].offset];
      const float z = xyzi[i * stride + 2];
      if (current.has_data() && z > current.z) continue;  // the common case: not lower
      const LidarCell cell = make_cell(i);
      if (!current.has_data() || cell.lower_than(current)) current = cell;
    }
  }
}

void LidarLayer::merge(const LidarLayer& other) {
  if (other.resolution_m_ != resolution_m_)
    throw InternalError("", "", "merging LiDAR layers of different resolutions");
  other.cells_.for_each([&](CellIndex c, const LidarCell& cell) {
    if (cell.has_data()) offer(c, cell);
  });
}

size_t LidarLayer::covered_cells() const {
  size_t n = 0;
  cells_.for_each([&](CellIndex, const LidarCell& cell) { n += cell.has_data(); });
  return n;
}

}  // namespace nsg::raster

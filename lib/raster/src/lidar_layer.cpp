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

static_assert(kBlockCells == 64, "add_points bins with shifts and masks of 64");

// The sweep's local block table: kTableBlocks² block pointers centred on the block of
// the sweep's first point (±16 blocks = ±204 m at 0.2 m, beyond any sweep's range), so a
// point finds its block without a map lookup; points outside go through the map.
constexpr int64_t kTableBlocks = 32;
thread_local std::vector<LidarCell*> block_table;

// Points are binned in chunks: cells for a chunk in one vectorized pass, then the
// scalar lowest-z update.
constexpr size_t kChunk = 1024;
struct ChunkCells {
  int32_t col[kChunk], row[kChunk];
  int32_t exact[kChunk];  // int32 like the cells: no packing in the vector loop
};
thread_local ChunkCells chunk_cells;

// floor(x / res) exactly as cell_of computes it, but with a multiplication by 1/res (the
// two divisions per point cost more than the rest of the binning): the product differs
// from the quotient by a few ulps (< 1e-6 of a cell below 1e9 cells), so exact[i] = 0
// marks a value that close to a cell border, or beyond ±1e9 cells, for cell_of to redo.
__attribute__((target_clones("avx2", "default"))) void cells_of_chunk(const float* __restrict x,
                                                                      const float* __restrict y, size_t n,
                                                                      double inv_res, int32_t* __restrict col,
                                                                      int32_t* __restrict row,
                                                                      int32_t* __restrict exact) {
  for (size_t i = 0; i < n; ++i) {
    const double ux = x[i] * inv_res, uy = y[i] * inv_res;
    // Clamped so the int32 conversion is defined for any finite or infinite input (the
    // reader rejects NaN); such points are flagged for cell_of below anyway.
    const double qx = ux > 1e9 ? 1e9 : (ux < -1e9 ? -1e9 : ux), qy = uy > 1e9 ? 1e9 : (uy < -1e9 ? -1e9 : uy);
    int32_t c = static_cast<int32_t>(qx), r = static_cast<int32_t>(qy);
    c -= static_cast<double>(c) > qx;  // truncation → floor
    r -= static_cast<double>(r) > qy;
    const double fx = qx - static_cast<double>(c), fy = qy - static_cast<double>(r);
    col[i] = c;
    row[i] = r;
    // `&`, not `&&`: no branches, so the loop vectorizes.
    exact[i] = static_cast<int32_t>((std::abs(ux) < 1e9) & (std::abs(uy) < 1e9) & (fx >= 1e-6) & (fx <= 1.0 - 1e-6) &
                                    (fy >= 1e-6) & (fy <= 1.0 - 1e-6));
  }
}

// The strided form's points as columns (tests and tools call it; the sweep loop does not).
struct ColumnBuffers {
  std::vector<float> x, y, z, intensity;
};
thread_local ColumnBuffers column_buffers;

}  // namespace

void LidarLayer::add_points(const float* xyzi, size_t count, size_t stride, int32_t sweep_id,
                            const int32_t* point_ids) {
  ColumnBuffers& b = column_buffers;
  b.x.resize(count);
  b.y.resize(count);
  b.z.resize(count);
  b.intensity.resize(count);
  for (size_t i = 0; i < count; ++i) {
    const float* p = xyzi + i * stride;
    b.x[i] = p[0], b.y[i] = p[1], b.z[i] = p[2], b.intensity[i] = p[3];
  }
  add_points({b.x.data(), b.y.data(), b.z.data(), b.intensity.data(), point_ids, count}, sweep_id);
}

void LidarLayer::add_points(const Columns& pts, int32_t sweep_id) {
  if (pts.count == 0) return;
  const double inv_res = 1.0 / resolution_m_;
  const CellIndex first = cell_of(pts.x[0], pts.y[0], resolution_m_);
  const int64_t bx0 = SparseGrid<LidarCell>::floor_div(first.col) - kTableBlocks / 2;
  const int64_t by0 = SparseGrid<LidarCell>::floor_div(first.row) - kTableBlocks / 2;
  block_table.assign(kTableBlocks * kTableBlocks, nullptr);
  SparseGrid<LidarCell>::Cursor cursor;  // for points outside the table
  ChunkCells& cc = chunk_cells;
  for (size_t start = 0; start < pts.count; start += kChunk) {
    const size_t n = std::min(kChunk, pts.count - start);
    cells_of_chunk(pts.x + start, pts.y + start, n, inv_res, cc.col, cc.row, cc.exact);
    for (size_t k = 0; k < n; ++k) {
      const size_t i = start + k;
      int64_t col = cc.col[k], row = cc.row[k];
      if (!cc.exact[k]) [[unlikely]] {
        const CellIndex c = cell_of(pts.x[i], pts.y[i], resolution_m_);
        col = c.col;
        row = c.row;
      }
      const uint64_t tx = static_cast<uint64_t>((col >> 6) - bx0), ty = static_cast<uint64_t>((row >> 6) - by0);
      LidarCell* current;
      if ((tx | ty) < static_cast<uint64_t>(kTableBlocks)) [[likely]] {
        LidarCell*& block = block_table[ty * kTableBlocks + tx];
        if (block == nullptr) [[unlikely]]
          block = cells_.block_data(col >> 6, row >> 6);
        current = block + (((row & 63) << 6) | (col & 63));
      } else {
        current = &cells_.at({col, row}, cursor);
      }
      // Most points are not lower than what the cell holds (an empty cell's z is +inf):
      // decide on z before building; equal heights go on to the full tie-break.
      if (pts.z[i] > current->z) continue;
      LidarCell cell;
      cell.x = pts.x[i];
      cell.y = pts.y[i];
      cell.z = pts.z[i];
      // = clamp(lround(intensity), 0, 255) without the libm call (exact in double).
      cell.intensity = static_cast<uint8_t>(std::clamp(static_cast<double>(pts.intensity[i]), 0.0, 255.0) + 0.5);
      cell.sweep = sweep_id;
      cell.point = pts.point_ids ? pts.point_ids[i] : static_cast<int32_t>(i);
      if (!current->has_data() || cell.lower_than(*current)) *current = cell;
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

#include "nsg/raster/lidar_layer.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

#include "nsg/core/error.h"
#include "nsg/geometry/transform.h"
#include "nsg/raster/raster_options.h"
#include "sweep_kernel.h"

namespace nsg::raster {

void LidarOptions::validate() const {
  lidar_option_table().check(*this);
  // Not a key of its own: generate's resolution_m sets it.
  if (!(resolution_m > 0.0)) throw ConfigError("", "resolution_m", "metres per pixel > 0");
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

namespace {

using sweep_kernel::kRecentreBlocks;
using sweep_kernel::kTableBlocks;

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

void LidarLayer::centre_table(int64_t bx, int64_t by) {
  BlockTable& table = table_;
  if (table.cells.empty() || std::abs(bx - (table.bx0 + kTableBlocks / 2)) > kRecentreBlocks ||
      std::abs(by - (table.by0 + kTableBlocks / 2)) > kRecentreBlocks) {
    table.bx0 = bx - kTableBlocks / 2;
    table.by0 = by - kTableBlocks / 2;
    table.cells.assign(kTableBlocks * kTableBlocks + 1, nullptr);  // + the null slot
    table.z.assign(kTableBlocks * kTableBlocks + 1, nullptr);
    table.z_used = 0;  // the z copies are refilled as blocks enter the new table
  }
}

void LidarLayer::attach_block(size_t slot, int64_t bx, int64_t by) {
  constexpr size_t kCells = size_t{kBlockCells} * kBlockCells;
  LidarCell* block = cells_.block_data(bx, by);
  BlockTable& table = table_;
  if (table.z_used == table.z_storage.size())
    table.z_storage.push_back(std::make_unique_for_overwrite<float[]>(kCells));
  float* z = table.z_storage[table.z_used++].get();
  for (size_t i = 0; i < kCells; ++i) z[i] = block[i].z;
  table.cells[slot] = block;
  table.z[slot] = z;
}

void LidarLayer::add_points(const Columns& pts, int32_t sweep_id) {
  if (pts.count == 0) return;
  const double inv_res = 1.0 / resolution_m_;
  const CellIndex first = cell_of(pts.x[0], pts.y[0], resolution_m_);
  centre_table(SparseGrid<LidarCell>::floor_div(first.col), SparseGrid<LidarCell>::floor_div(first.row));
  SparseGrid<LidarCell>::Cursor cursor;  // for points outside the table
  ChunkCells& cc = chunk_cells;
  for (size_t start = 0; start < pts.count; start += kChunk) {
    const size_t n = std::min(kChunk, pts.count - start);
    cells_of_chunk(pts.x + start, pts.y + start, n, inv_res, cc.col, cc.row, cc.exact);
    for (size_t k = 0; k < n; ++k) {
      const size_t i = start + k;
      const PointRef p{pts.x[i], pts.y[i], pts.z[i], pts.intensity[i],
                       pts.point_ids ? pts.point_ids[i] : static_cast<int32_t>(i)};
      update_cell(p, cc.col[k], cc.row[k], cc.exact[k] != 0, sweep_id, cursor);
    }
  }
}

namespace {

// The portable sweep path's buffers: kept points as columns (the transforms and the
// binning are vectorized loops over columns); reused across sweeps.
struct SweepColumns {
  std::vector<float> x, y, z, intensity;
  std::vector<int32_t> ids;
};
thread_local SweepColumns sweep_columns;

}  // namespace

size_t LidarLayer::add_sweep_portable(const float* rows5, size_t count, int32_t first_row,
                                      const geometry::Rigid3& ego_from_sensor, const geometry::Rigid3& global_from_ego,
                                      const LidarOptions& options, int32_t sweep_id, int64_t& bad_row) {
  // Checked before anything is added (this path is not the fast one).
  if (const int64_t bad = sweep_kernel::first_non_finite_row(rows5, count); bad >= 0) {
    bad_row = first_row + bad;
    return 0;
  }
  SweepColumns& buf = sweep_columns;
  // The filter runs in the sensor frame (devkit remove_close, as select_sweep_points);
  // only the kept points are transformed. Branch-free: every point is written, the count
  // advances only for kept ones (a kept/dropped branch per point mispredicts often).
  const double roof = options.roof_half_size_m, range2 = options.max_range_m * options.max_range_m;
  for (std::vector<float>* column : {&buf.x, &buf.y, &buf.z, &buf.intensity}) column->resize(count);
  buf.ids.resize(count);
  size_t n = 0;
  for (size_t i = 0; i < count; ++i) {
    const float* p = rows5 + 5 * i;
    const double x = p[0], y = p[1];
    const bool dropped = (std::abs(x) < roof && std::abs(y) < roof) || x * x + y * y > range2;
    buf.x[n] = p[0], buf.y[n] = p[1], buf.z[n] = p[2], buf.intensity[n] = p[3];
    buf.ids[n] = first_row + static_cast<int32_t>(i);
    n += !dropped;
  }
  geometry::transform_points_devkit_columns(ego_from_sensor, buf.x.data(), buf.y.data(), buf.z.data(), n);
  geometry::transform_points_devkit_columns(global_from_ego, buf.x.data(), buf.y.data(), buf.z.data(), n);
  add_points({buf.x.data(), buf.y.data(), buf.z.data(), buf.intensity.data(), buf.ids.data(), n}, sweep_id);
  return n;
}

size_t LidarLayer::add_sweep(const float* rows5, size_t count, int32_t first_row,
                             const geometry::Rigid3& ego_from_sensor, const geometry::Rigid3& global_from_ego,
                             const LidarOptions& options, int32_t sweep_id, SweepPath path,
                             int64_t* first_non_finite_row) {
  const bool fused = path == SweepPath::kFused || path == SweepPath::kFusedAvx2;
  if (first_row < 0 || count > static_cast<size_t>(std::numeric_limits<int32_t>::max() - first_row))
    throw InternalError("", "", "sweep rows beyond int32 point indices");
  if (fused && !fused_kernel_available())
    throw InternalError("", "", "the fused LiDAR sweep kernel needs a CPU with AVX2");
  int64_t bad_row = -1;
  const size_t kept =
      path == SweepPath::kPortable || !fused_kernel_available()
          ? add_sweep_portable(rows5, count, first_row, ego_from_sensor, global_from_ego, options, sweep_id, bad_row)
          : add_sweep_fused(rows5, count, first_row, ego_from_sensor, global_from_ego, options, sweep_id,
                            path != SweepPath::kFusedAvx2, bad_row);
  if (first_non_finite_row != nullptr) *first_non_finite_row = bad_row;
  else if (bad_row >= 0)
    throw DataError("", "point " + std::to_string(bad_row), "finite x, y, z, intensity and ring in every sweep row");
  return kept;
}

void LidarLayer::merge(const LidarLayer& other) {
  if (other.resolution_m_ != resolution_m_)
    throw InternalError("", "", "merging LiDAR layers of different resolutions");
  covered_cells_ += cells_.merge(other.cells_, [](LidarCell& current, const LidarCell& cell) {
    if (!current.has_data() || cell.lower_than(current)) current = cell;
  });
  // The merge packed the blocks it touched: the sweep loop's block pointers are stale.
  table_.cells.clear();
  table_.z.clear();
  table_.z_used = 0;
}

void LidarLayer::clear() {
  cells_.clear();
  covered_cells_ = 0;
  table_.cells.clear();  // the next sweep recentres it
  table_.z.clear();
  table_.z_used = 0;  // the z copies are kept for reuse
}

}  // namespace nsg::raster

#include "nsg/raster/lidar_layer.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "nsg/core/error.h"
#include "nsg/geometry/transform.h"
#include "sweep_kernel.h"

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

namespace {

using sweep_kernel::kRecentreBlocks;
using sweep_kernel::kTableBlocks;

// Points are binned in chunks: cells for a chunk in one vectorized pass, then the
// scalar lowest-z update.
constexpr size_t kChunk = 1024;
struct ChunkCells {
  int32_t col[kChunk], row[kChunk];
  int32_t exact[kChunk];  // int32 like the cells: no packing in the vector loop
  uint16_t candidates[kChunk];  // chunk offsets the scalar update must look at
};
static_assert(kChunk <= 65536, "candidates are uint16 offsets");
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

// Screening: most points of a sweep (≈ 90 % on the synthetic releases) are higher than
// what their cell holds already. The AVX2 screen decides that for 8 points at once with
// gathers (block pointer from the table, then the cell's z) and lists the rest — lower or
// equal z, a cell outside the table or in a block not allocated yet, a cell_of redo — as
// candidates for the scalar update, which decides everything again exactly. A stale z in
// the screen (two points of one group in one cell) only makes an extra candidate: z only
// ever decreases. Without AVX2 every point is a candidate.
size_t screen_all(size_t n, uint16_t* candidates) {
  for (size_t k = 0; k < n; ++k) candidates[k] = static_cast<uint16_t>(k);
  return n;
}

#if defined(__x86_64__)
__attribute__((target("avx2"))) size_t screen_avx2(const ChunkCells& cc, const float* z, size_t n,
                                                   LidarCell* const* table, int32_t bx0, int32_t by0,
                                                   uint16_t* candidates) {
  static_assert(sizeof(LidarCell) == 24 && offsetof(LidarCell, z) == 0, "the screen gathers z at block + 24·offset");
  const __m256i v_bx0 = _mm256_set1_epi32(bx0), v_by0 = _mm256_set1_epi32(by0);
  const __m256i v_size = _mm256_set1_epi32(static_cast<int32_t>(kTableBlocks)), v_minus1 = _mm256_set1_epi32(-1);
  const __m256i v_63 = _mm256_set1_epi32(63), v_zero = _mm256_setzero_si256();
  const __m256i even_lanes = _mm256_setr_epi32(0, 2, 4, 6, 0, 2, 4, 6);
  size_t m = 0, k = 0;
  for (; k + 8 <= n; k += 8) {
    const __m256i col = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(cc.col + k));
    const __m256i row = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(cc.row + k));
    const __m256i exact = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(cc.exact + k));
    const __m256i tx = _mm256_sub_epi32(_mm256_srai_epi32(col, 6), v_bx0);
    const __m256i ty = _mm256_sub_epi32(_mm256_srai_epi32(row, 6), v_by0);
    __m256i in = _mm256_and_si256(_mm256_cmpgt_epi32(tx, v_minus1), _mm256_cmpgt_epi32(v_size, tx));
    in = _mm256_and_si256(in, _mm256_and_si256(_mm256_cmpgt_epi32(ty, v_minus1), _mm256_cmpgt_epi32(v_size, ty)));
    in = _mm256_andnot_si256(_mm256_cmpeq_epi32(exact, v_zero), in);
    const __m256i t = _mm256_add_epi32(_mm256_mullo_epi32(ty, v_size), tx);
    const __m256i offset = _mm256_or_si256(_mm256_slli_epi32(_mm256_and_si256(row, v_63), 6), _mm256_and_si256(col, v_63));
    const __m256i bytes = _mm256_mullo_epi32(offset, _mm256_set1_epi32(static_cast<int32_t>(sizeof(LidarCell))));
    __m128 cz[2];
    __m256i valid64[2];
    for (int h = 0; h < 2; ++h) {  // lanes 0–3, then 4–7 (64-bit pointers: four per register)
      const __m128i t_h = h ? _mm256_extracti128_si256(t, 1) : _mm256_castsi256_si128(t);
      const __m256i in_h = _mm256_cvtepi32_epi64(h ? _mm256_extracti128_si256(in, 1) : _mm256_castsi256_si128(in));
      const __m256i block = _mm256_mask_i32gather_epi64(v_zero, reinterpret_cast<const long long*>(table), t_h, in_h, 8);
      valid64[h] = _mm256_andnot_si256(_mm256_cmpeq_epi64(block, v_zero), in_h);
      const __m256i addr = _mm256_add_epi64(
          block, _mm256_cvtepi32_epi64(h ? _mm256_extracti128_si256(bytes, 1) : _mm256_castsi256_si128(bytes)));
      const __m128 valid32 = _mm256_castps256_ps128(
          _mm256_castsi256_ps(_mm256_permutevar8x32_epi32(valid64[h], even_lanes)));
      cz[h] = _mm256_mask_i64gather_ps(_mm_setzero_ps(), static_cast<const float*>(nullptr), addr, valid32, 1);
    }
    const __m256i valid = _mm256_permute2x128_si256(_mm256_permutevar8x32_epi32(valid64[0], even_lanes),
                                                    _mm256_permutevar8x32_epi32(valid64[1], even_lanes), 0x20);
    const __m256 cell_z = _mm256_set_m128(cz[1], cz[0]);
    const __m256 lower_or_equal = _mm256_cmp_ps(_mm256_loadu_ps(z + k), cell_z, _CMP_LE_OQ);
    const __m256 candidate = _mm256_or_ps(lower_or_equal, _mm256_castsi256_ps(_mm256_xor_si256(valid, v_minus1)));
    for (unsigned bits = static_cast<unsigned>(_mm256_movemask_ps(candidate)); bits != 0; bits &= bits - 1)
      candidates[m++] = static_cast<uint16_t>(k + static_cast<size_t>(__builtin_ctz(bits)));
  }
  for (; k < n; ++k) candidates[m++] = static_cast<uint16_t>(k);
  return m;
}
#endif

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
  if (table.z_used == table.z_storage.size()) table.z_storage.push_back(std::make_unique_for_overwrite<float[]>(kCells));
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
  const int64_t bx0 = table_.bx0, by0 = table_.by0;
  LidarCell** block_table = table_.cells.data();
  SparseGrid<LidarCell>::Cursor cursor;  // for points outside the table
  ChunkCells& cc = chunk_cells;
#if defined(__x86_64__)
  static const bool has_avx2 = __builtin_cpu_supports("avx2");
  const bool use_avx2 = has_avx2 && sweep_kernel::table_fits_int32(bx0, by0);
#endif
  for (size_t start = 0; start < pts.count; start += kChunk) {
    const size_t n = std::min(kChunk, pts.count - start);
    cells_of_chunk(pts.x + start, pts.y + start, n, inv_res, cc.col, cc.row, cc.exact);
#if defined(__x86_64__)
    const size_t m = use_avx2 ? screen_avx2(cc, pts.z + start, n, block_table, static_cast<int32_t>(bx0),
                                            static_cast<int32_t>(by0), cc.candidates)
                              : screen_all(n, cc.candidates);
#else
    const size_t m = screen_all(n, cc.candidates);
#endif
    for (size_t j = 0; j < m; ++j) {
      const size_t k = cc.candidates[j];
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

size_t LidarLayer::add_sweep_portable(const float* rows5, size_t count, const geometry::Rigid3& ego_from_sensor,
                                      const geometry::Rigid3& global_from_ego, const LidarOptions& options,
                                      int32_t sweep_id) {
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
    buf.ids[n] = static_cast<int32_t>(i);
    n += !dropped;
  }
  geometry::transform_points_devkit_columns(ego_from_sensor, buf.x.data(), buf.y.data(), buf.z.data(), n);
  geometry::transform_points_devkit_columns(global_from_ego, buf.x.data(), buf.y.data(), buf.z.data(), n);
  add_points({buf.x.data(), buf.y.data(), buf.z.data(), buf.intensity.data(), buf.ids.data(), n}, sweep_id);
  return n;
}

size_t LidarLayer::add_sweep(const float* rows5, size_t count, const geometry::Rigid3& ego_from_sensor,
                             const geometry::Rigid3& global_from_ego, const LidarOptions& options, int32_t sweep_id,
                             SweepPath path) {
  const bool fused = path == SweepPath::kFused || path == SweepPath::kFusedAvx2;
  if (fused && !fused_kernel_available())
    throw InternalError("", "", "the fused LiDAR sweep kernel needs a CPU with AVX2");
  if (path == SweepPath::kPortable || !fused_kernel_available())
    return add_sweep_portable(rows5, count, ego_from_sensor, global_from_ego, options, sweep_id);
  return add_sweep_fused(rows5, count, ego_from_sensor, global_from_ego, options, sweep_id,
                         path != SweepPath::kFusedAvx2);
}

void LidarLayer::merge(const LidarLayer& other) {
  if (other.resolution_m_ != resolution_m_)
    throw InternalError("", "", "merging LiDAR layers of different resolutions");
  // Cells come block by block: the cursor makes that one map lookup per block, not per cell.
  // (The block table's z copies may go stale-high here: still safe, see BlockTable.)
  SparseGrid<LidarCell>::Cursor cursor;
  other.cells_.for_each([&](CellIndex c, const LidarCell& cell) {
    if (!cell.has_data()) return;
    LidarCell& current = cells_.at(c, cursor);
    if (!current.has_data() || cell.lower_than(current)) current = cell;
  });
}

size_t LidarLayer::covered_cells() const {
  size_t n = 0;
  cells_.for_each([&](CellIndex, const LidarCell& cell) { n += cell.has_data(); });
  return n;
}

}  // namespace nsg::raster

// The fused sweep kernel (LidarLayer::add_sweep_fused), per chunk of 2048 raw .pcd.bin
// rows: (A) load 8 rows (AVX2) or 16 (AVX-512), check every value is finite,
// de-interleave, roof/range filter, compact the kept points into columns (L1/L2-resident);
// (B1) both devkit transforms, the cells and the block-table slot of each point (AVX2, or
// AVX-512F for the float64 products and 16-lane binning); (B2) the screen: one scalar load
// per point of the table's compact z copy, no dependency between points so the cache
// misses overlap; (C) the exact scalar update of the candidates (LidarLayer::offer_point,
// shared with the portable path; the cell comes from B1's slot where it has one).
//
// Bit-exactness: every rounding is the portable path's, in its order — the filter's
// decisions are the float64 test's (AVX-512 decides in float32 only where that provably
// agrees), each transform is ((r0·x + r1·y) + r2·z) in double rounded to float32 then +
// float32 translation. Cells come from a float32 product with a proven error margin;
// points within the margin of a border go to cell_of, so every cell equals cell_of's.
// The TU is built with -ffp-contract=off (no product is fused, also where AVX-512F brings
// FMA instructions) and is not compiled with -mavx2: only the functions carrying target
// attributes use AVX2/AVX-512, and they run only after the CPU check.
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>

#if defined(__x86_64__)
// GCC 12's AVX-512 conversion intrinsics start from _mm512_undefined_*(), which trips a
// false -Wmaybe-uninitialized once inlined (GCC PR105593, fixed in 13).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <immintrin.h>
#pragma GCC diagnostic pop
#endif

#include <array>
#include <limits>

#include "nsg/core/error.h"
#include "nsg/geometry/transform.h"
#include "sweep_kernel.h"

namespace nsg::raster {

#if defined(__x86_64__)

namespace {

using sweep_kernel::kTableBlocks;

// Raw rows per chunk: the chunk's columns (≈ 36 KB) stay in L1/L2 between the stages.
constexpr size_t kRawChunk = 2048;
static_assert(kRawChunk <= 65536, "candidates are uint16 offsets");

struct FusedChunk {
  // Kept points of the chunk (+8: the compaction stores whole vectors; stage B reads
  // whole groups), transformed in place to the global frame by stage B.
  // (+16 and 64-byte alignment: the AVX-512 stage works on groups of 16.)
  alignas(64) float x[kRawChunk + 16], y[kRawChunk + 16], z[kRawChunk + 16], intensity[kRawChunk + 16];
  alignas(64) int32_t ids[kRawChunk + 16];
  alignas(64) int32_t col[kRawChunk + 16], row[kRawChunk + 16], exact[kRawChunk + 16];
  // Where stage B2 finds each point's cell z: its block table slot (the table's always-null
  // last slot when the point cannot be screened) and the cell's offset in the block.
  alignas(64) int32_t slot[kRawChunk + 16], offset[kRawChunk + 16];
  uint16_t candidates[kRawChunk + 8];
};
thread_local FusedChunk fused_chunk;

// How many candidates ahead stage C prefetches their cells.
constexpr size_t kPrefetchAhead = 24;

// The z a point "sees" when it cannot be screened: nothing is higher, so it is a candidate.
constexpr float kNoScreen = std::numeric_limits<float>::infinity();

// For each 8-bit keep mask, the kept lanes in order (the rest padded with 0): the
// permutation that packs them to the front.
constexpr std::array<std::array<uint8_t, 8>, 256> kCompactLanes = [] {
  std::array<std::array<uint8_t, 8>, 256> t{};
  for (unsigned m = 0; m < 256; ++m) {
    unsigned k = 0;
    for (uint8_t lane = 0; lane < 8; ++lane)
      if ((m >> lane) & 1u) t[m][k++] = lane;
  }
  return t;
}();

// A devkit transform as plain numbers: the float64 rotation and the float32 translation.
struct DevkitTransform {
  double r[9];
  float t[3];
};

DevkitTransform devkit_of(const geometry::Rigid3& tf) {
  const Eigen::Matrix3d& m = tf.rotation;
  return {{m(0, 0), m(0, 1), m(0, 2), m(1, 0), m(1, 1), m(1, 2), m(2, 0), m(2, 1), m(2, 2)},
          {static_cast<float>(tf.translation.x()), static_cast<float>(tf.translation.y()),
           static_cast<float>(tf.translation.z())}};
}

#define NSG_AVX2_INLINE __attribute__((target("avx2"), always_inline)) inline

NSG_AVX2_INLINE __m128 low_half(__m256 v) { return _mm256_castps256_ps128(v); }
NSG_AVX2_INLINE __m128 high_half(__m256 v) { return _mm256_extractf128_ps(v, 1); }
NSG_AVX2_INLINE __m256 load_rows(const float* low, const float* high) {
  return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(low)), _mm_loadu_ps(high), 1);
}

// Drop mask of 4 points in double, as the portable filter:
// (|x| < roof && |y| < roof) || x² + y² > range² (ordered compares: false on NaN, like C++).
NSG_AVX2_INLINE int dropped_bits(__m128 xf, __m128 yf, __m256d roof, __m256d range2) {
  const __m256d sign = _mm256_set1_pd(-0.0);
  const __m256d x = _mm256_cvtps_pd(xf), y = _mm256_cvtps_pd(yf);
  const __m256d in_roof = _mm256_and_pd(_mm256_cmp_pd(_mm256_andnot_pd(sign, x), roof, _CMP_LT_OQ),
                                        _mm256_cmp_pd(_mm256_andnot_pd(sign, y), roof, _CMP_LT_OQ));
  const __m256d far = _mm256_cmp_pd(_mm256_add_pd(_mm256_mul_pd(x, x), _mm256_mul_pd(y, y)), range2, _CMP_GT_OQ);
  return _mm256_movemask_pd(_mm256_or_pd(in_roof, far));
}

// Stage A's rows [i, n) after the last whole vector group, one at a time: the finite
// check and the filter in scalar double; returns the new kept count (from m).
size_t filter_tail(const float* rows5, size_t i, size_t n, int32_t first_id, double roof, double range2,
                   int64_t& bad_row, FusedChunk& c, size_t m) {
  for (; i < n; ++i) {
    const float* p = rows5 + 5 * i;
    if (sweep_kernel::first_non_finite_row(p, 1) == 0) [[unlikely]] {
      bad_row = static_cast<int64_t>(i);
      return m;
    }
    const double x = p[0], y = p[1];
    const bool dropped = (std::abs(x) < roof && std::abs(y) < roof) || x * x + y * y > range2;
    c.x[m] = p[0], c.y[m] = p[1], c.z[m] = p[2], c.intensity[m] = p[3];
    c.ids[m] = first_id + static_cast<int32_t>(i);
    m += !dropped;
  }
  return m;
}

// Stage A: rows [0, n) of `rows5` (ids first_id + row) → kept points packed into c's
// columns; returns how many. Every value (ring too) is checked for Inf/NaN on the way:
// at the first group holding one, `bad_row` gets that row (in rows5) and the stage stops
// (nothing of the group is added; the caller reports the row).
__attribute__((target("avx2"))) size_t filter_compact(const float* rows5, size_t n, int32_t first_id, double roof,
                                                      double range2, int64_t& bad_row, FusedChunk& c) {
  const __m256d v_roof = _mm256_set1_pd(roof), v_range2 = _mm256_set1_pd(range2);
  const __m256i lanes = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256i exponent = _mm256_set1_epi32(static_cast<int32_t>(sweep_kernel::kFloatExponent));
  size_t m = 0, i = 0;
  for (; i + 8 <= n; i += 8) {
    const float* p = rows5 + 5 * i;
    __m256i bad = _mm256_setzero_si256();  // the 8 rows' 40 values as five vectors
    for (int r = 0; r < 5; ++r) {
      const __m256i w = _mm256_and_si256(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(p + 8 * r)), exponent);
      bad = _mm256_or_si256(bad, _mm256_cmpeq_epi32(w, exponent));
    }
    if (!_mm256_testz_si256(bad, bad)) [[unlikely]] {
      bad_row = static_cast<int64_t>(i) + sweep_kernel::first_non_finite_row(p, 8);
      return m;
    }
    // Rows i..i+3 in the low halves, i+4..i+7 in the high halves; a 4×4 transpose per
    // half gives x, y, z, intensity of the 8 rows (lanes in row order).
    const __m256 r0 = load_rows(p, p + 20), r1 = load_rows(p + 5, p + 25);
    const __m256 r2 = load_rows(p + 10, p + 30), r3 = load_rows(p + 15, p + 35);
    const __m256d t0 = _mm256_castps_pd(_mm256_unpacklo_ps(r0, r1)), t1 = _mm256_castps_pd(_mm256_unpackhi_ps(r0, r1));
    const __m256d t2 = _mm256_castps_pd(_mm256_unpacklo_ps(r2, r3)), t3 = _mm256_castps_pd(_mm256_unpackhi_ps(r2, r3));
    const __m256 x = _mm256_castpd_ps(_mm256_unpacklo_pd(t0, t2)), y = _mm256_castpd_ps(_mm256_unpackhi_pd(t0, t2));
    const __m256 z = _mm256_castpd_ps(_mm256_unpacklo_pd(t1, t3)), in = _mm256_castpd_ps(_mm256_unpackhi_pd(t1, t3));
    const int dropped = dropped_bits(low_half(x), low_half(y), v_roof, v_range2) |
                        (dropped_bits(high_half(x), high_half(y), v_roof, v_range2) << 4);
    const unsigned keep = ~static_cast<unsigned>(dropped) & 0xffu;
    const __m256i perm =
        _mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(kCompactLanes[keep].data())));
    const __m256i ids = _mm256_add_epi32(_mm256_set1_epi32(first_id + static_cast<int32_t>(i)), lanes);
    _mm256_storeu_ps(c.x + m, _mm256_permutevar8x32_ps(x, perm));
    _mm256_storeu_ps(c.y + m, _mm256_permutevar8x32_ps(y, perm));
    _mm256_storeu_ps(c.z + m, _mm256_permutevar8x32_ps(z, perm));
    _mm256_storeu_ps(c.intensity + m, _mm256_permutevar8x32_ps(in, perm));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(c.ids + m), _mm256_permutevar8x32_epi32(ids, perm));
    m += static_cast<size_t>(std::popcount(keep));
  }
  return filter_tail(rows5, i, n, first_id, roof, range2, bad_row, c, m);  // the last < 8 rows
}

// One devkit transform of 8 points in place: per half of 4, float → double,
// ((r0·x + r1·y) + r2·z) rounded to float32, then + the float32 translation.
NSG_AVX2_INLINE void transform8(const DevkitTransform& tf, __m256& x, __m256& y, __m256& z) {
  __m128 out[3][2];
  for (int h = 0; h < 2; ++h) {
    const __m256d px = _mm256_cvtps_pd(h ? high_half(x) : low_half(x));
    const __m256d py = _mm256_cvtps_pd(h ? high_half(y) : low_half(y));
    const __m256d pz = _mm256_cvtps_pd(h ? high_half(z) : low_half(z));
    for (int a = 0; a < 3; ++a) {
      const __m256d s = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(tf.r[3 * a]), px),
                                                    _mm256_mul_pd(_mm256_set1_pd(tf.r[3 * a + 1]), py)),
                                      _mm256_mul_pd(_mm256_set1_pd(tf.r[3 * a + 2]), pz));
      out[a][h] = _mm256_cvtpd_ps(s);
    }
  }
  x = _mm256_add_ps(_mm256_set_m128(out[0][1], out[0][0]), _mm256_set1_ps(tf.t[0]));
  y = _mm256_add_ps(_mm256_set_m128(out[1][1], out[1][0]), _mm256_set1_ps(tf.t[1]));
  z = _mm256_add_ps(_mm256_set_m128(out[2][1], out[2][0]), _mm256_set1_ps(tf.t[2]));
}

// The cell coordinate floor(v / res) of 8 values from one float32 product u = v·r,
// r = float32(1/res): |u − v/res| ≤ |v/res|·δ with δ = (relative error of r) + 2^-24
// (the product's rounding), so where u's fraction is more than `margin` = |u|·2δ + 2^-20
// from both cell borders, floor(u) is cell_of's floor of the float64 quotient (also
// rounded: far below the margin). Those lanes get all-ones in `exact`; the others (near a
// border, |u| ≥ 1/(2δ) where the margin reaches a cell, inf, NaN) go to cell_of.
NSG_AVX2_INLINE __m256i cells8(__m256 v, __m256 r, __m256 two_delta, __m256& exact) {
  const __m256 u = _mm256_mul_ps(v, r);
  const __m256 fl = _mm256_floor_ps(u);
  const __m256 f = _mm256_sub_ps(u, fl);
  const __m256 abs_u = _mm256_andnot_ps(_mm256_set1_ps(-0.0f), u);
  const __m256 margin = _mm256_add_ps(_mm256_mul_ps(abs_u, two_delta), _mm256_set1_ps(0x1p-20f));
  exact = _mm256_and_ps(_mm256_cmp_ps(f, margin, _CMP_GE_OQ),
                        _mm256_cmp_ps(f, _mm256_sub_ps(_mm256_set1_ps(1.0f), margin), _CMP_LE_OQ));
  return _mm256_cvttps_epi32(fl);
}

// Stage B1's second half for points k..k+7 already in the global frame: the cells
// (c.col/row/exact) and where B2 finds the cell z (block table slot, offset); points near
// a cell border or outside the table get the null slot.
struct BinParams {
  float inv_res, two_delta;
  int32_t bx0, by0;
};
NSG_AVX2_INLINE void bin8(FusedChunk& c, size_t k, __m256 x, __m256 y, const BinParams& p) {
  static_assert(kTableBlocks == 32, "slot = ty·32 + tx");
  __m256 exact_x, exact_y;
  const __m256i col = cells8(x, _mm256_set1_ps(p.inv_res), _mm256_set1_ps(p.two_delta), exact_x);
  const __m256i row = cells8(y, _mm256_set1_ps(p.inv_res), _mm256_set1_ps(p.two_delta), exact_y);
  const __m256i exact = _mm256_castps_si256(_mm256_and_ps(exact_x, exact_y));
  _mm256_store_si256(reinterpret_cast<__m256i*>(c.col + k), col);
  _mm256_store_si256(reinterpret_cast<__m256i*>(c.row + k), row);
  _mm256_store_si256(reinterpret_cast<__m256i*>(c.exact + k), exact);

  const __m256i v_size = _mm256_set1_epi32(static_cast<int32_t>(kTableBlocks)), v_minus1 = _mm256_set1_epi32(-1);
  const __m256i v_63 = _mm256_set1_epi32(63);
  const __m256i tx = _mm256_sub_epi32(_mm256_srai_epi32(col, 6), _mm256_set1_epi32(p.bx0));
  const __m256i ty = _mm256_sub_epi32(_mm256_srai_epi32(row, 6), _mm256_set1_epi32(p.by0));
  __m256i in = _mm256_and_si256(_mm256_cmpgt_epi32(tx, v_minus1), _mm256_cmpgt_epi32(v_size, tx));
  in = _mm256_and_si256(in, _mm256_and_si256(_mm256_cmpgt_epi32(ty, v_minus1), _mm256_cmpgt_epi32(v_size, ty)));
  in = _mm256_and_si256(in, exact);
  const __m256i t = _mm256_add_epi32(_mm256_slli_epi32(ty, 5), tx);
  const __m256i offset =
      _mm256_or_si256(_mm256_slli_epi32(_mm256_and_si256(row, v_63), 6), _mm256_and_si256(col, v_63));
  _mm256_store_si256(reinterpret_cast<__m256i*>(c.slot + k),
                     _mm256_blendv_epi8(_mm256_set1_epi32(sweep_kernel::kNullSlot), t, in));
  _mm256_store_si256(reinterpret_cast<__m256i*>(c.offset + k), offset);
}

// Stage B1 over the m kept points of c: both transforms (written back to c's columns),
// then bin8. No load here misses the cache, so the loop runs at compute speed; the cell
// loads (mostly misses) are B2's.
__attribute__((target("avx2"))) void transform_bin_avx2(FusedChunk& c, size_t m, const DevkitTransform& a,
                                                        const DevkitTransform& b, const BinParams& p) {
  for (size_t k = 0; k < m; k += 8) {
    __m256 x = _mm256_load_ps(c.x + k), y = _mm256_load_ps(c.y + k), z = _mm256_load_ps(c.z + k);
    transform8(a, x, y, z);
    transform8(b, x, y, z);
    _mm256_store_ps(c.x + k, x);
    _mm256_store_ps(c.y + k, y);
    _mm256_store_ps(c.z + k, z);
    bin8(c, k, x, y, p);
  }
}

// The same with the float64 arithmetic of the transforms on 8 lanes (AVX-512F): the same
// operations in the same order (per lane IEEE double, MXCSR rounding to nearest for the
// float32 conversion), half the instructions, and 32 registers hold both matrices.
#define NSG_AVX512_TARGET __attribute__((target("avx2,avx512f,avx512vl")))
NSG_AVX512_TARGET __attribute__((always_inline)) inline void transform8_avx512(const __m512d* r, const __m256* t,
                                                                               __m256& x, __m256& y, __m256& z) {
  const __m512d px = _mm512_cvtps_pd(x), py = _mm512_cvtps_pd(y), pz = _mm512_cvtps_pd(z);
  __m256 out[3];
  for (int a = 0; a < 3; ++a) {
    const __m512d s = _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(r[3 * a], px), _mm512_mul_pd(r[3 * a + 1], py)),
                                    _mm512_mul_pd(r[3 * a + 2], pz));
    out[a] = _mm256_add_ps(_mm512_cvtpd_ps(s), t[a]);
  }
  x = out[0], y = out[1], z = out[2];
}

// cells8 on 16 lanes (the same operations; floor = roundscale towards −inf).
NSG_AVX512_TARGET __attribute__((always_inline)) inline __m512i cells16(__m512 v, __m512 r, __m512 two_delta,
                                                                        __mmask16& exact) {
  const __m512 u = _mm512_mul_ps(v, r);
  const __m512 fl = _mm512_roundscale_ps(u, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
  const __m512 f = _mm512_sub_ps(u, fl);
  const __m512 margin = _mm512_add_ps(_mm512_mul_ps(_mm512_abs_ps(u), two_delta), _mm512_set1_ps(0x1p-20f));
  exact = _mm512_cmp_ps_mask(f, margin, _CMP_GE_OQ) &
          _mm512_cmp_ps_mask(f, _mm512_sub_ps(_mm512_set1_ps(1.0f), margin), _CMP_LE_OQ);
  return _mm512_cvttps_epi32(fl);
}

// bin8 on 16 lanes.
NSG_AVX512_TARGET __attribute__((always_inline)) inline void bin16(FusedChunk& c, size_t k, __m512 x, __m512 y,
                                                                   const BinParams& p) {
  __mmask16 exact_x, exact_y;
  const __m512 inv_res = _mm512_set1_ps(p.inv_res), two_delta = _mm512_set1_ps(p.two_delta);
  const __m512i col = cells16(x, inv_res, two_delta, exact_x);
  const __m512i row = cells16(y, inv_res, two_delta, exact_y);
  const __mmask16 exact = exact_x & exact_y;
  _mm512_store_si512(c.col + k, col);
  _mm512_store_si512(c.row + k, row);
  _mm512_store_si512(c.exact + k, _mm512_maskz_set1_epi32(exact, -1));
  const __m512i tx = _mm512_sub_epi32(_mm512_srai_epi32(col, 6), _mm512_set1_epi32(p.bx0));
  const __m512i ty = _mm512_sub_epi32(_mm512_srai_epi32(row, 6), _mm512_set1_epi32(p.by0));
  const __m512i size = _mm512_set1_epi32(static_cast<int32_t>(kTableBlocks));
  // Unsigned < 32: also rejects negative offsets.
  const __mmask16 in = exact & _mm512_cmplt_epu32_mask(tx, size) & _mm512_cmplt_epu32_mask(ty, size);
  const __m512i t = _mm512_add_epi32(_mm512_slli_epi32(ty, 5), tx);
  const __m512i v_63 = _mm512_set1_epi32(63);
  _mm512_store_si512(c.slot + k, _mm512_mask_blend_epi32(in, _mm512_set1_epi32(sweep_kernel::kNullSlot), t));
  _mm512_store_si512(c.offset + k,
                     _mm512_or_si512(_mm512_slli_epi32(_mm512_and_si512(row, v_63), 6), _mm512_and_si512(col, v_63)));
}

NSG_AVX512_TARGET __attribute__((always_inline)) inline __m512 join(__m256 low, __m256 high) {
  return _mm512_castpd_ps(_mm512_insertf64x4(_mm512_castpd256_pd512(_mm256_castps_pd(low)), _mm256_castps_pd(high), 1));
}

// Stage A on 16 rows at a time (AVX-512F): five loads, a permute per column and register
// pair, the filter in float32 where that decides exactly (below), a compress per column.
//
// The filter in float32: for a float x, (double)|x| < roof ⟺ |x| < roof_f, the smallest
// float ≥ roof. x² + y² > range² (float64) is decided by s = x²+y² in float32, whose
// relative error is ≤ 2.0001·2^-24: s > far_f (range²·(1 + 2^-20) rounded up) ⇒ far,
// s < near_f (range²·(1 − 2^-20) rounded down) ⇒ not far; a group with a lane in between
// (within ~1e-6 of the circle) or a NaN takes the float64 test of the AVX2 stage.
struct FloatFilter {
  float roof_f, near_f, far_f;
  bool usable;  // range² within [2^-60, 2^100]: no underflow or overflow worth a thought
};

float float_at_or_above(double v) {
  float f = static_cast<float>(v);
  if (static_cast<double>(f) < v) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}
float float_at_or_below(double v) {
  float f = static_cast<float>(v);
  if (static_cast<double>(f) > v) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
  return f;
}

FloatFilter float_filter(double roof, double range2) {
  FloatFilter f{};
  f.usable = range2 >= 0x1p-60 && range2 <= 0x1p100 && roof >= 0.0 && roof <= 0x1p100;
  if (!f.usable) return f;
  f.roof_f = float_at_or_above(roof);
  f.near_f = float_at_or_below(range2 * (1.0 - 0x1p-20));
  f.far_f = float_at_or_above(range2 * (1.0 + 0x1p-20));
  return f;
}

// Column `col` of 16 rows of 5 floats held in v[0..4] (row j's column at float 5j + col).
NSG_AVX512_TARGET __attribute__((always_inline)) inline __m512 column16(const __m512* v, int col) {
  alignas(64) int32_t low[16], high[16], last[16];
  __mmask16 from_high = 0, from_last = 0;
  for (int j = 0; j < 16; ++j) {  // folded to constants: col is a literal at every call
    const int flat = 5 * j + col;
    low[j] = flat & 31, high[j] = (flat - 32) & 31, last[j] = (flat - 64) & 15;
    from_high |= static_cast<__mmask16>((flat >= 32 && flat < 64) << j);
    from_last |= static_cast<__mmask16>((flat >= 64) << j);
  }
  const __m512 a = _mm512_permutex2var_ps(v[0], _mm512_load_si512(low), v[1]);
  const __m512 b = _mm512_permutex2var_ps(v[2], _mm512_load_si512(high), v[3]);
  return _mm512_mask_permutexvar_ps(_mm512_mask_blend_ps(from_high, a, b), from_last, _mm512_load_si512(last), v[4]);
}

NSG_AVX512_TARGET size_t filter_compact_avx512(const float* rows5, size_t n, int32_t first_id, double roof,
                                               double range2, const FloatFilter& ff, int64_t& bad_row, FusedChunk& c) {
  const __m512i exponent = _mm512_set1_epi32(static_cast<int32_t>(sweep_kernel::kFloatExponent));
  const __m512 roof_f = _mm512_set1_ps(ff.roof_f), near_f = _mm512_set1_ps(ff.near_f), far_f = _mm512_set1_ps(ff.far_f);
  const __m256d roof_d = _mm256_set1_pd(roof), range2_d = _mm256_set1_pd(range2);
  const __m512i lanes = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  size_t m = 0, i = 0;
  for (; i + 16 <= n; i += 16) {
    const float* p = rows5 + 5 * i;
    const __m512 v[5] = {_mm512_loadu_ps(p), _mm512_loadu_ps(p + 16), _mm512_loadu_ps(p + 32), _mm512_loadu_ps(p + 48),
                         _mm512_loadu_ps(p + 64)};
    __mmask16 bad = 0;
    for (int r = 0; r < 5; ++r)
      bad |= _mm512_cmpeq_epi32_mask(_mm512_and_si512(_mm512_castps_si512(v[r]), exponent), exponent);
    if (bad != 0) [[unlikely]] {
      bad_row = static_cast<int64_t>(i) + sweep_kernel::first_non_finite_row(p, 16);
      return m;
    }
    const __m512 x = column16(v, 0), y = column16(v, 1), z = column16(v, 2), in = column16(v, 3);
    const __mmask16 in_roof = _mm512_cmp_ps_mask(_mm512_abs_ps(x), roof_f, _CMP_LT_OQ) &
                              _mm512_cmp_ps_mask(_mm512_abs_ps(y), roof_f, _CMP_LT_OQ);
    const __m512 s = _mm512_add_ps(_mm512_mul_ps(x, x), _mm512_mul_ps(y, y));
    __mmask16 far = _mm512_cmp_ps_mask(s, far_f, _CMP_GT_OQ);
    const __mmask16 near = _mm512_cmp_ps_mask(s, near_f, _CMP_LT_OQ);
    __mmask16 dropped = in_roof | far;
    if (static_cast<__mmask16>(far | near) != 0xffff) [[unlikely]] {  // near the circle, or NaN: float64
      const __m256 x_lo = _mm512_castps512_ps256(x), y_lo = _mm512_castps512_ps256(y);
      const __m256 x_hi = _mm256_castpd_ps(_mm512_extractf64x4_pd(_mm512_castps_pd(x), 1));
      const __m256 y_hi = _mm256_castpd_ps(_mm512_extractf64x4_pd(_mm512_castps_pd(y), 1));
      dropped = static_cast<__mmask16>(dropped_bits(low_half(x_lo), low_half(y_lo), roof_d, range2_d) |
                                       (dropped_bits(high_half(x_lo), high_half(y_lo), roof_d, range2_d) << 4) |
                                       (dropped_bits(low_half(x_hi), low_half(y_hi), roof_d, range2_d) << 8) |
                                       (dropped_bits(high_half(x_hi), high_half(y_hi), roof_d, range2_d) << 12));
    }
    const __mmask16 keep = static_cast<__mmask16>(~dropped);
    const __m512i ids = _mm512_add_epi32(_mm512_set1_epi32(first_id + static_cast<int32_t>(i)), lanes);
    _mm512_storeu_ps(c.x + m, _mm512_maskz_compress_ps(keep, x));
    _mm512_storeu_ps(c.y + m, _mm512_maskz_compress_ps(keep, y));
    _mm512_storeu_ps(c.z + m, _mm512_maskz_compress_ps(keep, z));
    _mm512_storeu_ps(c.intensity + m, _mm512_maskz_compress_ps(keep, in));
    _mm512_storeu_si512(c.ids + m, _mm512_maskz_compress_epi32(keep, ids));
    m += static_cast<size_t>(std::popcount(static_cast<unsigned>(keep)));
  }
  return filter_tail(rows5, i, n, first_id, roof, range2, bad_row, c, m);  // the last < 16 rows
}

NSG_AVX512_TARGET void transform_bin_avx512(FusedChunk& c, size_t m, const DevkitTransform& a, const DevkitTransform& b,
                                            const BinParams& p) {
  __m512d ra[9], rb[9];
  __m256 ta[3], tb[3];
  for (int i = 0; i < 9; ++i) ra[i] = _mm512_set1_pd(a.r[i]), rb[i] = _mm512_set1_pd(b.r[i]);
  for (int i = 0; i < 3; ++i) ta[i] = _mm256_set1_ps(a.t[i]), tb[i] = _mm256_set1_ps(b.t[i]);
  for (size_t k = 0; k < m; k += 16) {  // two groups of 8 through the transforms, binned as 16
    __m256 x[2], y[2], z[2];
    for (int h = 0; h < 2; ++h) {
      const size_t i = k + 8 * static_cast<size_t>(h);
      x[h] = _mm256_load_ps(c.x + i), y[h] = _mm256_load_ps(c.y + i), z[h] = _mm256_load_ps(c.z + i);
      transform8_avx512(ra, ta, x[h], y[h], z[h]);
      transform8_avx512(rb, tb, x[h], y[h], z[h]);
      _mm256_store_ps(c.x + i, x[h]);
      _mm256_store_ps(c.y + i, y[h]);
      _mm256_store_ps(c.z + i, z[h]);
    }
    bin16(c, k, join(x[0], x[1]), join(y[0], y[1]), p);
  }
}
#undef NSG_AVX512_TARGET

// Stage B2: the candidates — points not higher than their cell's current z, or not
// screenable (null slot, or a block not allocated yet: kNoScreen). Scalar loads with no
// dependency between points (gathers are slow and serialise), so many cache misses are in
// flight at once. A stale z (two points of the chunk in one cell, one
// updated by stage C) cannot happen: stage C runs after; z only ever decreases, and a
// point is decided exactly by update_cell anyway. `!(z > cell)`: a NaN is a candidate.
size_t screen(FusedChunk& c, size_t m, float* const* z_table) {
  size_t nc = 0;
  for (size_t k = 0; k < m; ++k) {
    const float* block_z = z_table[c.slot[k]];
    const float* cell_z = block_z ? block_z + c.offset[k] : &kNoScreen;
    c.candidates[nc] = static_cast<uint16_t>(k);
    nc += !(c.z[k] > *cell_z);
  }
  return nc;
}

#undef NSG_AVX2_INLINE

}  // namespace

bool LidarLayer::fused_kernel_available() {
  static const bool has_avx2 = __builtin_cpu_supports("avx2");
  return has_avx2;
}

size_t LidarLayer::add_sweep_fused(const float* rows5, size_t count, int32_t first_row,
                                   const geometry::Rigid3& ego_from_sensor, const geometry::Rigid3& global_from_ego,
                                   const LidarOptions& options, int32_t sweep_id, bool allow_avx512, int64_t& bad_row) {
  // The table is centred on the ego position (the sweep lies within max range of it);
  // poses that far out (or not finite) take the portable path, which needs no int32.
  const double ex = global_from_ego.translation.x() / resolution_m_,
               ey = global_from_ego.translation.y() / resolution_m_;
  if (!(std::abs(ex) < 1e9 && std::abs(ey) < 1e9))
    return add_sweep_portable(rows5, count, first_row, ego_from_sensor, global_from_ego, options, sweep_id, bad_row);
  centre_table(SparseGrid<LidarCell>::floor_div(static_cast<int64_t>(std::floor(ex))),
               SparseGrid<LidarCell>::floor_div(static_cast<int64_t>(std::floor(ey))));
  if (!sweep_kernel::table_fits_int32(table_.bx0, table_.by0))
    return add_sweep_portable(rows5, count, first_row, ego_from_sensor, global_from_ego, options, sweep_id, bad_row);

  const DevkitTransform a = devkit_of(ego_from_sensor), b = devkit_of(global_from_ego);
  const double roof = options.roof_half_size_m, range2 = options.max_range_m * options.max_range_m;
  // float32(1/res) and its relative error (computed in float64: exact enough, the margin
  // has a factor 2 to spare), for cells8.
  const float inv_res = static_cast<float>(1.0 / resolution_m_);
  const double r_error = std::abs(static_cast<double>(inv_res) * resolution_m_ - 1.0) + 1e-15;
  const float two_delta = static_cast<float>(2.0 * (r_error + 0x1p-24));
  static const bool has_avx512 = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl");
  const bool wide = allow_avx512 && has_avx512;
  const FloatFilter filter = float_filter(roof, range2);
  const BinParams bin{inv_res, two_delta, static_cast<int32_t>(table_.bx0), static_cast<int32_t>(table_.by0)};
  FusedChunk& c = fused_chunk;
  SparseGrid<LidarCell>::Cursor cursor;  // for points outside the table
  size_t kept = 0;
  for (size_t start = 0; start < count; start += kRawChunk) {
    const size_t n = std::min(kRawChunk, count - start);
    const int32_t first_id = first_row + static_cast<int32_t>(start);
    int64_t bad = -1;
    const size_t m = wide && filter.usable
                         ? filter_compact_avx512(rows5 + 5 * start, n, first_id, roof, range2, filter, bad, c)
                         : filter_compact(rows5 + 5 * start, n, first_id, roof, range2, bad, c);
    if (bad >= 0) [[unlikely]] {  // this chunk is not added; the caller drops the sweep
      bad_row = first_row + static_cast<int64_t>(start) + bad;
      return kept;
    }
    kept += m;
    if (wide) transform_bin_avx512(c, m, a, b, bin);
    else transform_bin_avx2(c, m, a, b, bin);
    const size_t nc = screen(c, m, table_.z.data());
    for (size_t j = 0; j < nc; ++j) {
      // The candidates' cells are mostly cache misses (B2 read only the z copy): fetch a
      // few candidates ahead so the misses overlap.
      if (j + kPrefetchAhead < nc) {
        const size_t ahead = c.candidates[j + kPrefetchAhead];
        if (const LidarCell* block = table_.cells[static_cast<size_t>(c.slot[ahead])]) {
          // A 24-byte cell may straddle two cache lines: fetch both ends.
          const char* cell = reinterpret_cast<const char*>(block + c.offset[ahead]);
          __builtin_prefetch(cell, 1);
          __builtin_prefetch(cell + sizeof(LidarCell) - 1, 1);
        }
      }
      const size_t k = c.candidates[j];
      const PointRef p{c.x[k], c.y[k], c.z[k], c.intensity[k], c.ids[k]};
      // A screened point's slot holds its block (the null slot never does): stage B1 found
      // the cell already. The others (near a border, outside the table, new block) look it up.
      const size_t slot = static_cast<size_t>(c.slot[k]);
      if (LidarCell* block = table_.cells[slot]) [[likely]]
        offer_point(p, sweep_id, block[c.offset[k]], table_.z[slot][c.offset[k]]);
      else update_cell(p, c.col[k], c.row[k], c.exact[k] != 0, sweep_id, cursor);
    }
  }
  return kept;
}

#else  // not x86-64: the portable path only

bool LidarLayer::fused_kernel_available() { return false; }

size_t LidarLayer::add_sweep_fused(const float* rows5, size_t count, int32_t first_row,
                                   const geometry::Rigid3& ego_from_sensor, const geometry::Rigid3& global_from_ego,
                                   const LidarOptions& options, int32_t sweep_id, bool allow_avx512, int64_t& bad_row) {
  return add_sweep_portable(rows5, count, first_row, ego_from_sensor, global_from_ego, options, sweep_id, bad_row);
}

#endif

}  // namespace nsg::raster

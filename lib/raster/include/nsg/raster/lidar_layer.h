#pragma once
// The LiDAR layer: per 0.2 m cell the lowest point over all sweeps of a location (the
// paper's trick: the ground under a moving car is seen in other sweeps and is lower than
// the car, so moving objects vanish). Accumulation per scene, then an associative and
// commutative reduction, so the result depends neither on scene order nor thread count.
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "nsg/raster/sparse_grid.h"

namespace nsg::geometry {
struct Rigid3;
}

namespace nsg::raster {

struct LidarOptions {
  double resolution_m = 0.2;
  double roof_half_size_m = 1.0;  // drop |x| < this and |y| < this in the sensor frame (devkit remove_close)
  double max_range_m = 60.0;      // drop points farther (in the sensor's xy plane)
  void validate() const;          // the declared checks (raster_options.h); ConfigError naming the key
};

// "Lowest" between two cells' kept points: z, then the source (sweep, point) ids, so equal
// heights resolve the same way in every reduction order (LidarCell, LidarsegCell).
template <typename Cell>
bool lower_point(const Cell& a, const Cell& b) {
  if (a.z != b.z) return a.z < b.z;
  if (a.sweep != b.sweep) return a.sweep < b.sweep;
  return a.point < b.point;
}

// The kept point of a cell; "lowest" as lower_point.
struct LidarCell {
  float z = std::numeric_limits<float>::infinity();  // +inf = no data
  float x = 0.0f, y = 0.0f;                          // global position of the kept point
  uint8_t intensity = 0;
  int32_t sweep = -1;  // a stable sweep id (sample_data index in the database)
  int32_t point = -1;  // index of the point in its sweep file

  bool has_data() const { return sweep >= 0; }
  bool lower_than(const LidarCell& o) const { return lower_point(*this, o); }
};

class LidarLayer {
 public:
  explicit LidarLayer(double resolution_m = 0.2) : resolution_m_(resolution_m) {}

  // Adds one sweep already filtered and in the global frame: xyz (float32, stride
  // `stride` floats per point, intensity at offset 3) with the original point indices.
  void add_points(const float* xyzi, size_t count, size_t stride, int32_t sweep_id, const int32_t* point_ids = nullptr);
  // The same for points stored as columns (the sweep loop's layout: vectorized binning).
  struct Columns {
    const float* x = nullptr;
    const float* y = nullptr;
    const float* z = nullptr;
    const float* intensity = nullptr;
    const int32_t* point_ids = nullptr;  // nullptr: the points' positions
    size_t count = 0;
  };
  void add_points(const Columns& points, int32_t sweep_id);

  // How add_sweep runs: kAuto = kFused where the CPU has AVX2, else kPortable (the
  // column path). kFused: the fused AVX2 kernel, with its transforms on AVX-512F where the
  // CPU has it; kFusedAvx2: AVX2 only. All give identical layers (tests force each); the
  // fused kernel hands poses beyond ±2e8 m to the portable path. kFused/kFusedAvx2 on a
  // CPU without AVX2 throw InternalError.
  enum class SweepPath { kAuto, kPortable, kFused, kFusedAvx2 };
  static bool fused_kernel_available();
  // Adds one sweep as read from its .pcd.bin: `count` rows of 5 float32 (x, y, z,
  // intensity, ring) in the sensor frame. Drops the roof square and points beyond range
  // (as select_sweep_points), maps the rest sensor → ego → global with the devkit's float32
  // chain (bit-identical to transform_points_devkit twice) and keeps the lowest per cell;
  // cells name the point by its row in the file. A sweep may come in runs: `rows5` are
  // the file's rows [first_row, first_row + count). Returns the number of kept points.
  // Every value (ring too) must be finite, and is checked in the same pass (so a reader
  // need not, nuscenes::LidarFile::Check): the file row of the first row holding an Inf
  // or NaN goes to `first_non_finite_row` if given (−1 if none; when set, part of the
  // rows may have been added, so the caller drops the layer and reports the file), else
  // it is thrown as DataError.
  size_t add_sweep(const float* rows5, size_t count, int32_t first_row, const geometry::Rigid3& ego_from_sensor,
                   const geometry::Rigid3& global_from_ego, const LidarOptions& options, int32_t sweep_id,
                   SweepPath path = SweepPath::kAuto, int64_t* first_non_finite_row = nullptr);
  // Lowest-wins union with another layer of the same resolution. Leaves the blocks it
  // touches packed (a finished layer's form); adding sweeps afterwards unpacks
  // the blocks they reach.
  void merge(const LidarLayer& other);
  // Empties the layer but keeps its storage for the next sweeps (a lane's scratch layer,
  // refilled scene after scene, faults its memory in once).
  void clear();

  const SparseGrid<LidarCell>& cells() const { return cells_; }
  double resolution_m() const { return resolution_m_; }
  size_t covered_cells() const { return covered_cells_; }

 private:
  size_t add_sweep_portable(const float* rows5, size_t count, int32_t first_row,
                            const geometry::Rigid3& ego_from_sensor, const geometry::Rigid3& global_from_ego,
                            const LidarOptions& options, int32_t sweep_id, int64_t& bad_row);
  // Defined in sweep_kernel_avx2.cpp (compiled for any x86-64; the kernels carry
  // target("avx2") attributes and run only after the CPU check).
  size_t add_sweep_fused(const float* rows5, size_t count, int32_t first_row, const geometry::Rigid3& ego_from_sensor,
                         const geometry::Rigid3& global_from_ego, const LidarOptions& options, int32_t sweep_id,
                         bool allow_avx512, int64_t& bad_row);
  // Recentres table_ when block (bx, by) is more than a few blocks off its centre.
  void centre_table(int64_t bx, int64_t by);
  // The exact lowest-z update of point i of a batch (col/row from the vector binning when
  // `exact`, else redone by cell_of); shared by both paths so they decide identically.
  struct PointRef {
    float x, y, z, intensity;
    int32_t point;
  };
  void update_cell(const PointRef& p, int64_t col, int64_t row, bool exact, int32_t sweep_id,
                   SparseGrid<LidarCell>::Cursor& cursor);
  // The decision itself, on a cell found already (z_copy: its screen copy or a sink).
  void offer_point(const PointRef& p, int32_t sweep_id, LidarCell& current, float& z_copy);
  double resolution_m_;
  SparseGrid<LidarCell> cells_;
  size_t covered_cells_ = 0;  // cells with data, counted as they fill
  // The sweep loop's block pointers around the current sweeps (kept from sweep to sweep:
  // blocks move only when merge() packs them), so a point finds its block without a map
  // lookup; recentred when the sweeps move away.
  struct BlockTable {
    int64_t bx0 = 0, by0 = 0;  // block coordinates of entry 0
    std::vector<LidarCell*> cells;
    // Per slot with a block, a compact copy of its cells' z for the fused kernel's screen
    // (16 cells per cache line instead of 2.7). Every table write updates it and z only
    // decreases, so it is never below the cell's z: "higher than the copy" ⇒ "not lower
    // than the cell". merge() packs blocks, so it clears the table.
    std::vector<float*> z;
    std::vector<std::unique_ptr<float[]>> z_storage;  // arrays in use (the first z_used) and spare
    size_t z_used = 0;
  };
  // Puts block (bx, by) (allocated if new) and its z copy into table slot `slot`.
  void attach_block(size_t slot, int64_t bx, int64_t by);
  BlockTable table_;
};

// Keeps the points of a sweep (float32 × `stride`, sensor frame) outside the roof square
// and within range; returns their indices (so cells can name their source point).
std::vector<int32_t> select_sweep_points(const float* points, size_t count, size_t stride, const LidarOptions& options);

}  // namespace nsg::raster

#include "nsg/raster/lidarseg_layer.h"

#include <algorithm>

#include "nsg/core/error.h"
#include "nsg/core/parallel.h"
#include "nsg/nuscenes/database.h"
#include "nsg/nuscenes/lidar.h"
#include "nsg/nuscenes/lidarseg.h"
#include "nsg/raster/accumulate.h"

namespace nsg::raster {

using nuscenes::Database;
using nuscenes::Index;

namespace {

constexpr size_t kChunkSweeps = 16;     // sweeps in flight at once: bounds memory, not results
constexpr size_t kScratchBlocks = 256;  // dense blocks (64 KB each) before a fold into the packed layer

// A labelled point of one sweep, ready to bin.
struct LabelledPoint {
  CellIndex cell;
  LidarsegCell value;
};

struct SweepResult {
  std::vector<LabelledPoint> points;
  bool without_labels = false;
};

std::vector<Index> key_frame_sweeps(const Database& db, const std::vector<Index>& scenes, const std::string& channel) {
  std::vector<char> selected(db.scene.size(), 0);
  for (Index s : scenes) selected[static_cast<size_t>(s)] = 1;
  std::vector<Index> sweeps;
  for (Index i = 0; i < static_cast<Index>(db.sample_data.size()); ++i) {
    const nuscenes::SampleData& sd = db.sample_data[i];
    if (sd.modality != nuscenes::Modality::kLidar || !sd.is_key_frame || db.channel(sd) != channel) continue;
    if (selected[static_cast<size_t>(db.sample[sd.sample].scene)]) sweeps.push_back(i);
  }
  return sweeps;
}

SweepResult label_sweep(const Database& db, const nuscenes::LidarsegIndex& index, Index sweep,
                        const LidarOptions& options, const LidarsegClassTable& classes) {
  SweepResult out;
  const std::filesystem::path labels_file = index.labels_file(sweep);
  if (labels_file.empty()) {
    out.without_labels = true;
    return out;
  }
  std::vector<nuscenes::LidarPoint> points;
  nuscenes::read_lidar_points(db.file_path(db.sample_data[sweep]), points);
  std::vector<uint8_t> labels;
  nuscenes::read_lidarseg_labels(labels_file, points.size(), labels);
  // The LiDAR layer's filters, in the sensor frame, before the transform.
  const std::vector<int32_t> kept = select_sweep_points(reinterpret_cast<const float*>(points.data()), points.size(),
                                                        nuscenes::kLidarPointStrideFloats, options);
  nuscenes::sensor_to_global(db, sweep, points);
  for (int32_t i : kept) {
    const uint8_t cls = classes[labels[static_cast<size_t>(i)]];
    if (cls == 255) continue;
    const nuscenes::LidarPoint& p = points[static_cast<size_t>(i)];
    LidarsegCell value;
    value.z = p.z;
    value.sweep = static_cast<int32_t>(sweep);
    value.point = i;
    value.cls = cls;
    out.points.push_back({cell_of(p.x, p.y, options.resolution_m), value});
  }
  return out;
}

}  // namespace

LidarsegLayer accumulate_lidarseg(const Database& db, const std::vector<Index>& scenes, const LidarOptions& lidar,
                                  const std::string& lidar_channel, const LidarsegClassTable& classes, int threads) {
  check_scene_list(db, scenes);  // `lidar` was checked where it was read
  const nuscenes::LidarsegIndex index = nuscenes::LidarsegIndex::load(db);
  const std::vector<Index> sweeps = key_frame_sweeps(db, scenes, lidar_channel);
  LidarsegLayer layer;
  layer.stats.sweeps = sweeps.size();
  std::vector<SweepResult> results;
  // Points land in dense scratch blocks, folded into the packed layer every few hundred
  // blocks (the layer then keeps only its labelled cells); lowest-wins is
  // order-free, so when the folds happen does not show.
  SparseGrid<LidarsegCell> scratch;
  SparseGrid<LidarsegCell>::Cursor cursor;
  const auto fold = [&] {
    layer.cells.merge(scratch, [&](LidarsegCell& into, const LidarsegCell& from) {
      if (!into.has_data()) ++layer.stats.cells;
      if (!into.has_data() || from.lower_than(into)) into = from;
    });
    scratch = {};
    cursor = {};
  };
  for (size_t first = 0; first < sweeps.size(); first += kChunkSweeps) {
    const size_t n = std::min(kChunkSweeps, sweeps.size() - first);
    results.assign(n, {});
    parallel_for(n, threads, [&](size_t k) { results[k] = label_sweep(db, index, sweeps[first + k], lidar, classes); });
    for (const SweepResult& r : results) {
      layer.stats.sweeps_without_labels += r.without_labels;
      layer.stats.points_labelled += r.points.size();
      for (const LabelledPoint& p : r.points) {
        LidarsegCell& cell = scratch.at(p.cell, cursor);
        if (!cell.has_data() || p.value.lower_than(cell)) cell = p.value;
      }
    }
    if (scratch.block_count() >= kScratchBlocks) fold();
  }
  fold();
  return layer;
}

// Block by block: each colour block written is packed before the next, so the overlay never
// holds more than one dense block (the layer over every tile of a city, dense, was 218 MB).
void overlay_semantics(ColorLayer& color, const LidarsegLayer& lidarseg, const std::vector<CellRect>& regions) {
  std::vector<CellRect> near;  // the regions overlapping the block at hand
  const auto inside = [&](CellIndex c) {
    return regions.empty() || std::any_of(near.begin(), near.end(), [&](const CellRect& r) { return r.contains(c); });
  };
  lidarseg.cells.for_each_block([&](int64_t bx, int64_t by, const LidarsegCell* cells) {
    const CellRect block{bx * kBlockCells, by * kBlockCells, (bx + 1) * kBlockCells, (by + 1) * kBlockCells};
    near.clear();
    for (const CellRect& r : regions)
      if (r.col0 < block.col1 && block.col0 < r.col1 && r.row0 < block.row1 && block.row0 < r.row1) near.push_back(r);
    if (!regions.empty() && near.empty()) return;
    ColorCell* out = nullptr;
    for (int r = 0; r < kBlockCells; ++r)
      for (int c = 0; c < kBlockCells; ++c) {
        const LidarsegCell& cell = cells[r * kBlockCells + c];
        if (!cell.has_data() || !inside({bx * kBlockCells + c, by * kBlockCells + r})) continue;
        if (out == nullptr) out = color.cells_.block_data(bx, by);
        ColorCell& o = out[r * kBlockCells + c];
        if (!(o.flags & kCoverageSemantic)) ++color.semantic_cells_;
        o.semantic = cell.cls;
        o.flags |= kCoverageSemantic;
      }
    if (out != nullptr) color.cells_.pack_block(bx, by);
  });
}

}  // namespace nsg::raster

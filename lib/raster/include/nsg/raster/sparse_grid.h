#pragma once
// Sparse square blocks of cells over a location's map frame (DESIGN.md §4, §8): a block
// is allocated only when data falls into it, so memory grows with the covered area,
// never with the map canvas. Cell (col, row) covers [col·res, (col+1)·res) ×
// [row·res, (row+1)·res) in map metres (column = floor(x / res), row = floor(y / res)).
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <vector>

namespace nsg::raster {

inline constexpr int kBlockCells = 64;  // 64 × 64 cells = 12.8 m at 0.2 m/px

struct CellIndex {
  int64_t col = 0;
  int64_t row = 0;
  bool operator==(const CellIndex&) const = default;
};

inline CellIndex cell_of(double x_m, double y_m, double resolution_m) {
  return {static_cast<int64_t>(std::floor(x_m / resolution_m)),
          static_cast<int64_t>(std::floor(y_m / resolution_m))};
}

// A sparse grid of T. T must be default-constructible into its "no data" state.
template <typename T>
class SparseGrid {
 public:
  struct BlockKey {
    int64_t bx = 0, by = 0;
    bool operator<(const BlockKey& o) const { return by != o.by ? by < o.by : bx < o.bx; }
  };
  using Block = std::vector<T>;  // kBlockCells², row-major (row = y)

  T& at(CellIndex c) {
    const BlockKey k = block_of(c);
    return block_for(k)[offset(c, k)];
  }
  // The last block used, so runs of nearby cells (a sweep's points come in scan order)
  // skip the map lookup. Valid while the grid lives; blocks never move once allocated.
  struct Cursor {
    BlockKey key;
    Block* block = nullptr;
  };
  T& at(CellIndex c, Cursor& cursor) {
    const BlockKey k = block_of(c);
    if (cursor.block == nullptr || k.bx != cursor.key.bx || k.by != cursor.key.by) {
      cursor.block = &block_for(k);
      cursor.key = k;
    }
    return (*cursor.block)[offset(c, k)];
  }
  // nullptr when the block was never touched.
  const T* find(CellIndex c) const {
    const BlockKey k = block_of(c);
    auto it = blocks_.find(k);
    return it == blocks_.end() ? nullptr : &(*it->second)[offset(c, k)];
  }
  // The cells of block (bx, by), row-major, allocated on first use; for bulk writers
  // that bucket their cells by block first.
  T* block_data(int64_t bx, int64_t by) { return block_for({bx, by}).data(); }
  // floor(a / kBlockCells): the block coordinate of a cell coordinate.
  static int64_t floor_div(int64_t a) { return a >= 0 ? a / kBlockCells : -((-a + kBlockCells - 1) / kBlockCells); }

  size_t block_count() const { return blocks_.size(); }
  size_t memory_bytes() const { return blocks_.size() * kBlockCells * kBlockCells * sizeof(T); }

  // Visits every cell of every allocated block in a fixed order (blocks by (by, bx),
  // cells row-major): f(CellIndex, T&).
  template <typename F>
  void for_each(F&& f) {
    for (auto& [k, block] : blocks_)
      for (int r = 0; r < kBlockCells; ++r)
        for (int c = 0; c < kBlockCells; ++c)
          f(CellIndex{k.bx * kBlockCells + c, k.by * kBlockCells + r}, (*block)[r * kBlockCells + c]);
  }
  // Visits every allocated block in the same order: f(bx, by, const T* cells) with the
  // block's kBlockCells² cells row-major.
  template <typename F>
  void for_each_block(F&& f) const {
    for (const auto& [k, block] : blocks_) f(k.bx, k.by, block->data());
  }
  template <typename F>
  void for_each(F&& f) const {
    for (const auto& [k, block] : blocks_)
      for (int r = 0; r < kBlockCells; ++r)
        for (int c = 0; c < kBlockCells; ++c)
          f(CellIndex{k.bx * kBlockCells + c, k.by * kBlockCells + r}, (*block)[r * kBlockCells + c]);
  }

 private:
  Block& block_for(BlockKey k) {
    std::unique_ptr<Block>& block = blocks_[k];
    if (!block) block = std::make_unique<Block>(kBlockCells * kBlockCells);
    return *block;
  }
  static BlockKey block_of(CellIndex c) { return {floor_div(c.col), floor_div(c.row)}; }
  static size_t offset(CellIndex c, BlockKey k) {
    return static_cast<size_t>((c.row - k.by * kBlockCells) * kBlockCells + (c.col - k.bx * kBlockCells));
  }

  std::map<BlockKey, std::unique_ptr<Block>> blocks_;
};

}  // namespace nsg::raster

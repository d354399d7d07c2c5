// SparseGrid's packed blocks: a merged grid keeps only the cells holding data
// and reads exactly like the dense grid it came from, through every accessor.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

#include "nsg/core/rng.h"
#include "nsg/raster/sparse_grid.h"

namespace nsg::raster {
namespace {

struct Cell {
  int32_t value = -1;  // −1 = no data
  bool has_data() const { return value >= 0; }
};
using Grid = SparseGrid<Cell>;
using Truth = std::map<std::pair<int64_t, int64_t>, int32_t>;  // (col, row) → value

// ~`fill` of the cells of a 5 × 4-block area straddling the origin get a value.
Truth random_cells(uint64_t seed, double fill, Grid& grid) {
  Rng rng(seed);
  Truth truth;
  for (int64_t row = -100; row < 156; ++row)
    for (int64_t col = -130; col < 190; ++col)
      if (rng.uniform() < fill) {
        const auto value = static_cast<int32_t>(rng.uniform_int(0, 1000));
        grid.at({col, row}).value = value;
        truth[{col, row}] = value;
      }
  return truth;
}

void keep_max(Cell& into, const Cell& from) { into.value = std::max(into.value, from.value); }

// Every accessor of `grid` against `want`, over the blocks of `dense` (same block set).
void expect_same_cells(const Grid& grid, const Grid& dense) {
  ASSERT_EQ(grid.block_count(), dense.block_count());
  std::vector<std::pair<CellIndex, int32_t>> a, b;
  grid.for_each([&](CellIndex c, const Cell& x) { a.push_back({c, x.value}); });
  dense.for_each([&](CellIndex c, const Cell& x) { b.push_back({c, x.value}); });
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].first, b[i].first);
    ASSERT_EQ(a[i].second, b[i].second) << a[i].first.col << "," << a[i].first.row;
    const Cell* found = grid.find(a[i].first);
    ASSERT_NE(found, nullptr);
    ASSERT_EQ(found->value, b[i].second);
  }
  std::vector<Cell> buffer;
  size_t blocks = 0;
  grid.for_each_block([&](int64_t bx, int64_t by, const Cell* cells) {
    const Cell* want = dense.read_block(bx, by, buffer);
    ASSERT_NE(want, nullptr);
    for (size_t i = 0; i < Grid::kCells; ++i) ASSERT_EQ(cells[i].value, want[i].value);
    ++blocks;
  });
  EXPECT_EQ(blocks, grid.block_count());
}

TEST(SparseGrid, AMergedGridIsPackedAndReadsLikeTheDenseOne) {
  Grid dense;
  const Truth truth = random_cells(7, 0.3, dense);
  Grid packed;
  packed.merge(dense, keep_max);
  expect_same_cells(packed, dense);
  for (const auto& [cell, value] : truth) ASSERT_EQ(packed.find({cell.first, cell.second})->value, value);
  EXPECT_EQ(packed.find({100000, 0}), nullptr);  // an untouched block
  for (int64_t row = -100; row < -80; ++row)     // empty cells of packed blocks read as "no data"
    for (int64_t col = -130; col < -110; ++col)
      ASSERT_EQ(packed.find({col, row})->has_data(), truth.contains({col, row})) << col << "," << row;
  // 30 % filled: the packed cells plus the bitmaps take well under half the dense blocks.
  EXPECT_LT(packed.memory_bytes(), dense.memory_bytes() * 0.4);
  EXPECT_GT(packed.memory_bytes(), truth.size() * sizeof(Cell));
}

TEST(SparseGrid, PackingInPlaceKeepsEveryCellAndDropsEmptyBlocks) {
  Grid dense, packed;
  const Truth truth = random_cells(11, 0.2, dense);
  random_cells(11, 0.2, packed);
  packed.at({5000, 5000}) = Cell{};  // a block touched but left without data
  ASSERT_EQ(packed.block_count(), dense.block_count() + 1);
  packed.pack_block(SparseGrid<Cell>::floor_div(-130), SparseGrid<Cell>::floor_div(-100));  // one block first
  packed.pack_all();
  expect_same_cells(packed, dense);
  EXPECT_EQ(packed.find({5000, 5000}), nullptr);
  EXPECT_LT(packed.memory_bytes(), dense.memory_bytes() * 0.35);
  packed.at({-130, -100}).value = 5;  // a packed block takes writes again
  packed.pack_block(SparseGrid<Cell>::floor_div(-130), SparseGrid<Cell>::floor_div(-100));
  EXPECT_EQ(packed.find({-130, -100})->value, 5);
  ASSERT_FALSE(truth.empty());
}

TEST(SparseGrid, CountsCellsWithDataInAnyWindowOfABlock) {
  Grid dense;
  random_cells(11, 0.45, dense);
  Grid packed;
  packed.merge(dense, keep_max);
  Rng rng(3);
  for (int trial = 0; trial < 2000; ++trial) {
    const int64_t bx = rng.uniform_int(-3, 3), by = rng.uniform_int(-2, 3);
    int c0 = static_cast<int>(rng.uniform_int(0, 64)), c1 = static_cast<int>(rng.uniform_int(0, 64));
    int r0 = static_cast<int>(rng.uniform_int(0, 64)), r1 = static_cast<int>(rng.uniform_int(0, 64));
    if (trial % 10 == 0) c0 = 0, c1 = 64;  // whole rows: the full-word mask
    if (c1 < c0) std::swap(c0, c1);
    if (r1 < r0) std::swap(r0, r1);
    size_t want = 0;
    for (int r = r0; r < r1; ++r)
      for (int c = c0; c < c1; ++c) {
        const Cell* cell = dense.find({bx * kBlockCells + c, by * kBlockCells + r});
        want += cell != nullptr && cell->has_data();
      }
    ASSERT_EQ(packed.count_with_data(bx, by, c0, c1, r0, r1), want) << bx << "," << by;
    ASSERT_EQ(dense.count_with_data(bx, by, c0, c1, r0, r1), want) << bx << "," << by;
  }
}

// Merging into packed blocks, writing into them (which unpacks them) and merging again
// gives what the same operations give on dense blocks.
TEST(SparseGrid, MergesAndWritesIntoPackedBlocksKeepEveryCell) {
  Grid a, b;
  random_cells(1, 0.2, a);
  random_cells(2, 0.2, b);
  Grid packed;
  packed.merge(a, keep_max);
  packed.merge(b, keep_max);
  packed.at({5, 5}).value = 5000;     // a packed block, unpacked by the write
  packed.at({9000, 9000}).value = 7;  // a new block
  Grid dense;                         // the same by plain writes
  for (const Grid* g : {&a, &b})
    g->for_each([&](CellIndex c, const Cell& x) {
      if (x.has_data()) keep_max(dense.at(c), x);
      else dense.at(c);  // the block exists in both
    });
  dense.at({5, 5}).value = 5000;
  dense.at({9000, 9000}).value = 7;
  expect_same_cells(packed, dense);
  Grid again;  // and packing a grid holding dense and packed blocks
  again.merge(packed, keep_max);
  expect_same_cells(again, dense);
}

// merge() returns the cells that were empty and hold data now: all of a new block's,
// and in a block both grids have, only those the other grid adds.
TEST(SparseGrid, MergeCountsTheCellsItCovers) {
  Grid a, b;
  const Truth in_a = random_cells(4, 0.25, a);
  const Truth in_b = random_cells(5, 0.25, b);
  b.at({20000, 0}).value = 1;  // a block only b has
  Grid merged;
  EXPECT_EQ(merged.merge(a, keep_max), in_a.size());
  size_t added = 1;
  for (const auto& [cell, value] : in_b) added += !in_a.contains(cell);
  EXPECT_EQ(merged.merge(b, keep_max), added);
  EXPECT_EQ(merged.merge(b, keep_max), 0u);  // nothing new the second time
}

// A cleared grid is empty, and the blocks it writes next (on kept storage) start empty.
TEST(SparseGrid, AClearedGridReusesItsStorageForEmptyBlocks) {
  Grid grid;
  random_cells(6, 0.5, grid);
  const size_t bytes = grid.memory_bytes(), blocks = grid.block_count();
  grid.clear();
  EXPECT_EQ(grid.block_count(), 0u);
  EXPECT_EQ(grid.find({0, 0}), nullptr);
  EXPECT_EQ(grid.memory_bytes(), blocks * Grid::kCells * sizeof(Cell));  // the storage is kept...
  Grid fresh;
  random_cells(8, 0.1, grid);  // ...and reused: no cell of the first fill shows
  random_cells(8, 0.1, fresh);
  ASSERT_EQ(grid.block_count(), blocks);
  expect_same_cells(grid, fresh);
  EXPECT_EQ(grid.memory_bytes(), bytes);  // the same blocks again: nothing new allocated
}

}  // namespace
}  // namespace nsg::raster

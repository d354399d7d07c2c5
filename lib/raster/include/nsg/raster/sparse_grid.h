#pragma once
// Sparse square blocks of cells over a location's map frame (docs/architecture.md): a block
// is allocated only when data falls into it, so memory grows with the covered area,
// never with the map canvas. Cell (col, row) covers [col·res, (col+1)·res) ×
// [row·res, (row+1)·res) in map metres (column = floor(x / res), row = floor(y / res)).
//
// A block is either dense (all kBlockCells² cells: what writers and the sweep kernel
// need) or packed (an occupancy bitmap and only the cells holding data: what a finished
// layer keeps: a city's LiDAR blocks are ~30 % filled). Writes unpack a block;
// merge() leaves the blocks it touches packed. Readers see the same cells either way.
#include <algorithm>
#include <array>
#include <bit>
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
  return {static_cast<int64_t>(std::floor(x_m / resolution_m)), static_cast<int64_t>(std::floor(y_m / resolution_m))};
}

// A sparse grid of T. T must be default-constructible into its "no data" state; packing
// (merge) also needs `bool T::has_data() const`.
template <typename T>
class SparseGrid {
  static_assert(kBlockCells == 64, "a packed block's occupancy row is one 64-bit word");

 public:
  static constexpr size_t kCells = static_cast<size_t>(kBlockCells) * kBlockCells;
  struct BlockKey {
    int64_t bx = 0, by = 0;
    bool operator<(const BlockKey& o) const { return by != o.by ? by < o.by : bx < o.bx; }
  };

  T& at(CellIndex c) {
    const BlockKey k = block_of(c);
    return dense_block(k)[offset(c, k)];
  }
  // The last block used, so runs of nearby cells (a sweep's points come in scan order)
  // skip the map lookup. Valid until the next merge() into this grid (which may pack the
  // block); blocks never move otherwise.
  struct Cursor {
    BlockKey key;
    T* cells = nullptr;
  };
  T& at(CellIndex c, Cursor& cursor) {
    const BlockKey k = block_of(c);
    if (cursor.cells == nullptr || k.bx != cursor.key.bx || k.by != cursor.key.by) {
      cursor.cells = dense_block(k);
      cursor.key = k;
    }
    return cursor.cells[offset(c, k)];
  }
  // nullptr when the block was never touched; a default ("no data") T for an empty cell.
  const T* find(CellIndex c) const {
    const BlockKey k = block_of(c);
    auto it = blocks_.find(k);
    return it == blocks_.end() ? nullptr : it->second->find(offset(c, k));
  }
  // The cells of block (bx, by), row-major, allocated (or unpacked) on first use; for bulk
  // writers that bucket their cells by block first.
  T* block_data(int64_t bx, int64_t by) { return dense_block({bx, by}); }
  // The kBlockCells² cells of block (bx, by) row-major, or nullptr when it was never
  // touched; a packed block is expanded into `buffer`, so the pointer lives as long as
  // `buffer` and the grid are unchanged.
  const T* read_block(int64_t bx, int64_t by, std::vector<T>& buffer) const {
    auto it = blocks_.find({bx, by});
    return it == blocks_.end() ? nullptr : it->second->cells(buffer);
  }
  // Cells holding data in columns [c0, c1) × rows [r0, r1) of block (bx, by) (block-local,
  // 0 ≤ c0 ≤ c1 ≤ kBlockCells); 0 for an untouched block. A packed block answers from its
  // bitmap.
  size_t count_with_data(int64_t bx, int64_t by, int c0, int c1, int r0, int r1) const {
    auto it = blocks_.find({bx, by});
    if (it == blocks_.end() || c1 <= c0) return 0;
    const Block& b = *it->second;
    size_t n = 0;
    if (b.is_packed()) {
      const uint64_t mask = (c1 - c0 == kBlockCells ? ~uint64_t{0} : ((uint64_t{1} << (c1 - c0)) - 1)) << c0;
      for (int r = r0; r < r1; ++r) n += static_cast<size_t>(std::popcount(b.occupied[r] & mask));
    } else {
      for (int r = r0; r < r1; ++r)
        for (int c = c0; c < c1; ++c) n += b.dense[static_cast<size_t>(r * kBlockCells + c)].has_data();
    }
    return n;
  }
  // floor(a / kBlockCells): the block coordinate of a cell coordinate.
  static int64_t floor_div(int64_t a) { return a >= 0 ? a / kBlockCells : -((-a + kBlockCells - 1) / kBlockCells); }

  size_t block_count() const { return blocks_.size(); }
  // The cells' storage and the blocks' bookkeeping (not the map's nodes: ~50 B a block).
  size_t memory_bytes() const {
    size_t bytes = 0;
    for (const auto& [k, block] : blocks_)
      bytes += sizeof(Block) + (block->dense.capacity() + block->packed.capacity()) * sizeof(T);
    return bytes + spare_.size() * kCells * sizeof(T);
  }

  // Visits every cell of every allocated block in a fixed order (blocks by (by, bx),
  // cells row-major; empty cells of packed blocks as T{}): f(CellIndex, const T&), the
  // reference valid during the call only (a packed block is expanded into a buffer).
  template <typename F>
  void for_each(F&& f) const {
    std::vector<T> buffer;
    for (const auto& [k, block] : blocks_) {
      const T* cells = block->cells(buffer);
      for (int r = 0; r < kBlockCells; ++r)
        for (int c = 0; c < kBlockCells; ++c)
          f(CellIndex{k.bx * kBlockCells + c, k.by * kBlockCells + r}, cells[r * kBlockCells + c]);
    }
  }
  // Visits every allocated block in the same order: f(bx, by, const T* cells) with the
  // block's kBlockCells² cells row-major (valid during the call).
  template <typename F>
  void for_each_block(F&& f) const {
    std::vector<T> buffer;
    for (const auto& [k, block] : blocks_) f(k.bx, k.by, block->cells(buffer));
  }

  // Folds `other` in block by block: combine(T& into, const T& from) for each cell of
  // `other` holding data. combine(T{}, from) must give `from` (an empty cell takes the
  // other's): a block new to this grid is copied, not combined. The blocks touched are
  // left packed (a finished layer's form); cursors and block_data pointers into this grid
  // are invalid afterwards. Returns the cells that held no data here and do now.
  template <typename Combine>
  size_t merge(const SparseGrid& other, Combine&& combine) {
    std::vector<T> from_buffer, into_buffer(kCells);
    size_t newly_covered = 0;
    for (const auto& [k, from_block] : other.blocks_) {
      const T* from = from_block->cells(from_buffer);
      auto [it, added] = blocks_.try_emplace(k);
      std::unique_ptr<Block>& slot = it->second;
      if (added) {
        slot = std::make_unique<Block>();
        slot->pack(from);
        if (slot->packed.empty()) blocks_.erase(it);  // as with at(): a block only where data fell
        else newly_covered += slot->packed.size();
        continue;
      }
      T* into = slot->is_packed() ? slot->expand(into_buffer.data()) : slot->dense.data();
      for (size_t i = 0; i < kCells; ++i) {
        if (!from[i].has_data()) continue;
        const bool had_data = into[i].has_data();
        combine(into[i], from[i]);
        newly_covered += !had_data && into[i].has_data();
      }
      slot->pack(into);
    }
    return newly_covered;
  }

  // Packs block (bx, by) if it is dense (a writer done with it); a block left without data
  // is dropped, as merge() does. Pointers into that block are invalid afterwards.
  void pack_block(int64_t bx, int64_t by) {
    auto it = blocks_.find({bx, by});
    if (it == blocks_.end() || it->second->is_packed()) return;
    it->second->pack(it->second->dense.data());
    if (it->second->packed.empty()) blocks_.erase(it);
  }
  // Packs every dense block: a finished layer's form (memory follows the cells holding
  // data). Cursors and block_data pointers are invalid afterwards.
  void pack_all() {
    for (auto it = blocks_.begin(); it != blocks_.end();) {
      if (!it->second->is_packed()) it->second->pack(it->second->dense.data());
      it = it->second->packed.empty() ? blocks_.erase(it) : std::next(it);
    }
  }

  // Drops every block but keeps the dense blocks' storage for the next writes (a layer
  // refilled scene after scene then allocates, and faults in, its memory once).
  void clear() {
    for (auto& [k, block] : blocks_)
      if (!block->is_packed()) spare_.push_back(std::move(block->dense));
    blocks_.clear();
  }

 private:
  struct Block {
    std::vector<T> dense;                          // kBlockCells² cells row-major; empty when packed
    std::vector<T> packed;                         // the cells holding data, row-major (packed blocks)
    std::array<uint64_t, kBlockCells> occupied{};  // bit c of word r: cell (c, r) is in `packed`
    std::array<uint16_t, kBlockCells> before{};    // packed cells in rows above r

    bool is_packed() const { return dense.empty(); }
    const T* find(size_t i) const {
      if (!is_packed()) return &dense[i];
      const uint64_t word = occupied[i / kBlockCells], bit = uint64_t{1} << (i % kBlockCells);
      if ((word & bit) == 0) return &kEmpty;
      return &packed[before[i / kBlockCells] + static_cast<size_t>(std::popcount(word & (bit - 1)))];
    }
    // All cells row-major: the dense array, or a packed block expanded into `buffer`.
    const T* cells(std::vector<T>& buffer) const {
      if (!is_packed()) return dense.data();
      buffer.resize(kCells);
      return expand(buffer.data());
    }
    T* expand(T* out) const {
      std::fill(out, out + kCells, T{});
      const T* next = packed.data();
      for (size_t r = 0; r < static_cast<size_t>(kBlockCells); ++r)
        for (uint64_t word = occupied[r]; word != 0; word &= word - 1)
          out[r * kBlockCells + static_cast<size_t>(std::countr_zero(word))] = *next++;
      return out;
    }
    // Keeps the cells of `cells` (kBlockCells² row-major, may be `dense`) holding data.
    void pack(const T* cells) {
      size_t n = 0;
      for (size_t r = 0; r < static_cast<size_t>(kBlockCells); ++r) {
        uint64_t word = 0;
        for (size_t c = 0; c < static_cast<size_t>(kBlockCells); ++c)
          word |= static_cast<uint64_t>(cells[r * kBlockCells + c].has_data()) << c;
        occupied[r] = word;
        before[r] = static_cast<uint16_t>(n);
        n += static_cast<size_t>(std::popcount(word));
      }
      std::vector<T> kept;
      kept.reserve(n);  // exactly n: a packed block holds no slack
      for (size_t r = 0; r < static_cast<size_t>(kBlockCells); ++r)
        for (uint64_t word = occupied[r]; word != 0; word &= word - 1)
          kept.push_back(cells[r * kBlockCells + static_cast<size_t>(std::countr_zero(word))]);
      packed = std::move(kept);
      std::vector<T>().swap(dense);
    }
    void unpack() {
      std::vector<T> all(kCells);
      expand(all.data());
      dense = std::move(all);
      std::vector<T>().swap(packed);
    }
  };
  static inline const T kEmpty{};

  T* dense_block(BlockKey k) {
    std::unique_ptr<Block>& block = blocks_[k];
    if (!block) {
      block = std::make_unique<Block>();
      if (!spare_.empty()) {  // a new block: reuse kept storage (empty cells, not packed)
        block->dense = std::move(spare_.back());
        spare_.pop_back();
        std::fill(block->dense.begin(), block->dense.end(), T{});
        return block->dense.data();
      }
    }
    if (block->is_packed()) block->unpack();
    return block->dense.data();
  }
  static BlockKey block_of(CellIndex c) { return {floor_div(c.col), floor_div(c.row)}; }
  static size_t offset(CellIndex c, BlockKey k) {
    return static_cast<size_t>((c.row - k.by * kBlockCells) * kBlockCells + (c.col - k.bx * kBlockCells));
  }

  std::map<BlockKey, std::unique_ptr<Block>> blocks_;
  std::vector<std::vector<T>> spare_;  // dense storage kept by clear(), kCells each
};

}  // namespace nsg::raster

#pragma once
// Split regions of a location (docs/architecture.md): named rectangles assigned to
// train / val / test, either given explicitly or cut automatically into square blocks of
// the LiDAR-covered extent and assigned by a seeded hash with target ratios. Regions of
// different splits are at least `buffer_m` apart, so no pixel of a test crop is ever
// seen in training (a crop must lie wholly inside one region).
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace nsg::raster {
class LidarLayer;
}

namespace nsg::options {
template <typename Owner>
class Table;  // nsg/core/options.h
}

namespace nsg::tiling {

inline constexpr std::array<std::string_view, 3> kSplitNames = {"train", "val", "test"};
bool is_split_name(std::string_view name);

// An axis-aligned rectangle in map metres.
struct RectM {
  double x_west_m = 0.0;
  double y_south_m = 0.0;
  double x_east_m = 0.0;
  double y_north_m = 0.0;

  double width_m() const { return x_east_m - x_west_m; }
  double height_m() const { return y_north_m - y_south_m; }
  bool valid() const { return x_west_m < x_east_m && y_south_m < y_north_m; }
  bool contains(const RectM& inner) const;
  // Distance between the two rectangles (0 when they touch or overlap).
  double distance_to(const RectM& other) const;
};

struct Region {
  std::string name;   // unique per location, e.g. "test-00" or a configured name
  std::string split;  // train | val | test
  RectM bounds;
};

struct SplitRatios {
  double train = 0.7;
  double val = 0.0;
  double test = 0.3;
};

struct SplitOptions {
  // Explicit regions of this location; empty = automatic blocks.
  std::vector<Region> regions;
  // Automatic blocks: edge length; 0 = chosen from the covered extent (see plan_regions).
  double block_size_m = 0.0;
  SplitRatios ratios;
  // Gap between regions of different splits; must be ≥ the crop size.
  double buffer_m = 51.2;
  // A block takes part only if at least this fraction of its cells hold LiDAR.
  double min_block_coverage = 0.05;
  // The declared checks and check_relations; ConfigError naming the key.
  void validate(double crop_size_m) const;
  // What one key cannot say alone: the buffer holds a crop, blocks hold a crop and the
  // buffer, the ratios sum to 1, explicit regions are sound and far enough apart.
  void check_relations(double crop_size_m) const;
};
// The config keys splits.* but splits.regions (nsg/core/options.h).
const options::Table<SplitOptions>& split_option_table();

// A half-open window of cells [col0, col1) × [row0, row1).
struct CellWindow {
  int64_t col0 = 0, row0 = 0, col1 = 0, row1 = 0;
  bool empty() const { return col1 <= col0 || row1 <= row0; }
};

// What plan_regions did with the ground it was given, so a run that ends with few or no
// crops can say which filter took them (generate's empty-dataset message).
struct RegionStats {
  bool explicit_regions = false;    // regions came from the config (the counts below stay 0)
  bool no_lidar = false;            // no cell holds LiDAR: nothing to cut into blocks
  double block_size_m = 0.0;        // automatic blocks: the edge used
  int64_t blocks = 0;               // automatic blocks on the grid over the covered extent
  int64_t blocks_low_coverage = 0;  // of them, below min_block_coverage
  // Per split (kSplitNames order): blocks assigned, and of them dropped as smaller than a
  // crop once the buffers to other splits were cut off.
  std::array<int64_t, 3> blocks_assigned{};
  std::array<int64_t, 3> blocks_too_small{};
};

// Position of a split name in kSplitNames (train 0, val 1, test 2); -1 for others.
int split_index(std::string_view split);

// The bounding window of the LiDAR cells holding a point (empty when there are none).
CellWindow covered_window(const raster::LidarLayer& lidar);

// The regions of one location. Explicit regions are checked (valid rectangles, split
// names, unique names, the buffer between different splits) and returned as given.
// Automatic: blocks on a grid anchored at the covered extent's south-west corner; blocks
// with enough coverage are ordered by mix64(seed, block) and the first round(n·test)
// become test, the next round(n·val) val, the rest train (at least one test block when
// the test ratio is > 0 and there are ≥ 2 blocks); then every block next to (or diagonal
// to) a block of a different split gives up `buffer_m` on that side — train blocks give
// way to val/test, val to test — so different splits never come closer than the buffer.
// Blocks too small for one crop after that are dropped.
// `stats` (optional) receives the counts above.
std::vector<Region> plan_regions(const raster::LidarLayer& lidar, const SplitOptions& options, double crop_size_m,
                                 uint64_t seed, RegionStats* stats = nullptr);

// The smallest distance between regions of different splits (infinity when one split only).
double min_split_gap_m(const std::vector<Region>& regions);

}  // namespace nsg::tiling

#pragma once
// Crop sampling inside split regions (docs/architecture.md): crops are aligned to the
// 0.2 m cell grid, lie wholly inside one region and are kept only when enough of their
// cells hold LiDAR. Train crops go to random positions (a count per km² of covered area,
// or a total); val/test crops to a non-overlapping grid (random on request).
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "nsg/tiling/regions.h"

namespace nsg::raster {
class LidarLayer;
}

namespace nsg::tiling {

enum class Placement { kRandom, kGrid };

struct CropOptions {
  int size_px = 256;
  double min_lidar_coverage = 0.5;  // fraction of the crop's cells holding LiDAR
  Placement train = Placement::kRandom;
  Placement val = Placement::kGrid;
  Placement test = Placement::kGrid;
  // Random placement: wanted crops = per_km2 × covered km² of the region, or `total`
  // spread over the split's regions by covered area when > 0.
  double random_per_km2 = 1500.0;
  int64_t random_total = 0;
  int attempts_per_crop = 20;  // random draws per wanted crop before giving up
  void validate() const;       // the declared checks; ConfigError naming the key
};
// The config keys crops.* (nsg/core/options.h).
const options::Table<CropOptions>& crop_option_table();

struct Crop {
  std::string region;  // Region::name
  std::string split;
  int64_t col0 = 0;  // south-west cell of the crop (cells [col0, col0+size) × [row0, row0+size))
  int64_t row0 = 0;
  double lidar_coverage = 0.0;
  RectM bounds(double resolution_m, int size_px) const;
};

// Where the candidate crops of one split went (plan_crops), for the message of a run that
// ends with few or none: every window tested is either kept or below the coverage threshold.
struct SplitCropStats {
  int64_t regions = 0;              // regions of this split
  int64_t regions_no_room = 0;      // no whole crop fits on the cell grid inside the region
  int64_t regions_none_wanted = 0;  // random placement: the region's share rounds to 0 crops
  double covered_km2 = 0.0;         // LiDAR-covered area inside the split's regions
  int64_t wanted = 0;               // random placement: crops asked for
  int64_t windows = 0;              // candidate windows tested (grid positions, random draws)
  int64_t below_coverage = 0;       // of them, under min_lidar_coverage (or without LiDAR)
  int64_t kept = 0;
  double best_rejected_coverage = 0.0;  // the highest coverage among the rejected windows
};
struct CropStats {
  std::array<SplitCropStats, 3> splits{};  // kSplitNames order
};

// Fraction of the cells of the size×size window at (col0, row0) that hold LiDAR; reads
// only the blocks under the window.
double window_coverage(const raster::LidarLayer& lidar, int64_t col0, int64_t row0, int size_px);
// LiDAR-covered cells inside a rectangle (cells whose centre lies inside).
int64_t covered_cells_in(const raster::LidarLayer& lidar, const RectM& rect);

// The crops of one location: regions in order, each region's crops in placement order
// (grid: south to north, west to east; random: draw order). Deterministic for a seed;
// each region draws from its own RNG stream (hash of the region name), so adding a
// region does not move the crops of another.
// `stats` (optional) receives the counts above.
std::vector<Crop> plan_crops(const raster::LidarLayer& lidar, const std::vector<Region>& regions,
                             const CropOptions& options, uint64_t seed, CropStats* stats = nullptr);

}  // namespace nsg::tiling

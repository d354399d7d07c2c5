#pragma once
// The camera layers (docs/architecture.md): every kept LiDAR point of a
// location is coloured from the key-frame camera images near it. A view is usable when the
// point projects inside the image (devkit bounds 1 < u < W−1, 1 < v < H−1) with depth >
// min_depth_m and no LiDAR return of that key frame hides it; the closest usable view
// wins, RGB bilinear from the (scaled-decoded) JPEG, class of the nearest full-size pixel
// from the mask (stored full size or at 1/n of it: the mask pixel covering that pixel).
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "nsg/core/coverage_bits.h"
#include "nsg/core/progress.h"
#include "nsg/raster/lidar_layer.h"
#include "nsg/raster/sparse_grid.h"

namespace nsg::nuscenes {
class Database;
struct SampleData;
}  // namespace nsg::nuscenes

namespace nsg::raster {

// The coverage bits are core/coverage_bits.h's; raster:: names kept for the layers' code.
using ::nsg::kCoverageLidar;
using ::nsg::kCoverageRgb;
using ::nsg::kCoverageSemantic;

struct ColorCell {
  uint8_t r = 0, g = 0, b = 0;
  uint8_t semantic = 255;  // 255 = no class
  uint8_t flags = 0;       // kCoverageRgb | kCoverageSemantic (LiDAR = 1 comes from LidarLayer)
  float depth_m = std::numeric_limits<float>::infinity();  // depth of the winning view
  // Every writer sets a coverage flag with the cell's data; the layer is packed on it.
  bool has_data() const { return flags != 0; }
};

// Half-open cell ranges [col0, col1) × [row0, row1).
struct CellRect {
  int64_t col0 = 0, row0 = 0, col1 = 0, row1 = 0;
  bool contains(CellIndex c) const { return c.col >= col0 && c.col < col1 && c.row >= row0 && c.row < row1; }
};

// Where the semantic layer comes from: class-id masks of the camera images (projected like
// RGB), nuScenes-lidarseg's per-point labels of the key-frame sweeps (lidarseg_layer.h), or
// whichever of the two the release has (resolve_semantic_source, before a run).
enum class SemanticSource { kMasks, kLidarseg, kAuto };

struct CameraOptions {
  bool rgb = true;
  bool semantic = true;
  SemanticSource semantic_source = SemanticSource::kAuto;
  std::filesystem::path semantic_root;  // empty = <dataroot>/semantic; masks at <root>/<CHANNEL>/<basename>.png,
                                        // the image's size or 1/n of it (n ≤ 8, sides rounded up)
  // lidarseg label → our class (a labels file, schemas/v1/segment-labels.schema.json);
  // empty = the built-in copy of samples/semantic-labels/nuscenes-lidarseg.json.
  std::filesystem::path lidarseg_labels;
  double view_radius_m = 40.0;  // key-frame ego poses farther (in xy) from the point are not considered
  double min_depth_m = 1.0;     // devkit min_dist
  // Occlusion: the view is rejected when a LiDAR return of the image's key frame is closer
  // by more than occlusion_margin_m and stands above the point's line of sight: it projects
  // within ± occlusion_side_px sideways (0 = one step between the sweep's columns in the
  // image, 2π·rings / points radians: ≈ 7 px for a real 34 720-point sweep), and from
  // occlusion_height_m above the line of sight up to occlusion_window_px (full-resolution
  // pixels) higher in the image. Flat ground in front of a point lies below its line of
  // sight and never hides it, even where the rings are dense at a grazing angle; an object
  // hiding the point rises above the line, and one of its rings is within the window (the
  // LiDAR's beam spacing is ≈ 29 px at 1266 px focal, 32 beams over 41°).
  int occlusion_window_px = 40;
  int occlusion_side_px = 0;
  double occlusion_height_m = 0.05;
  double occlusion_margin_m = 0.15;
  int jpeg_scale_denom = 2;                 // 1, 2 or 4 (turbojpeg scaled decode)
  std::string lidar_channel = "LIDAR_TOP";  // the key-frame sweep used for occlusion (set by lidar.channel)
  // The declared checks (raster_options.h) for options built in code; ConfigError naming the
  // key (both rgb and semantic off is valid).
  void validate() const;
  // True when the semantic layer comes from the camera masks (read by the colouring).
  bool semantic_masks() const { return semantic && semantic_source == SemanticSource::kMasks; }
};

// camera.semantic_source "auto" made concrete for one release, before a run reads it (so
// a dataset's manifest records what was used): masks when the mask root (semantic_root,
// or <dataroot>/semantic) is a folder — the camera segmentation the paper projects, made
// by `nsgraph segment` or shipped with the release; else lidarseg when
// <dataroot>/<version>/lidarseg.json holds records (the test split's is empty); else no
// semantic layer (camera.semantic off),
// with one notice line. Real releases ship neither, so the defaults work on them. Other
// sources and camera.semantic off are left as they are. Returns what it chose, as the
// config value ("masks", "lidarseg", "none"), or "" when there was nothing to choose.
std::string resolve_semantic_source(CameraOptions& camera, const std::filesystem::path& dataroot,
                                    const std::string& version);

// Where the colouring reads the class-id mask of key-frame camera image `sd`:
// <semantic_root or dataroot/semantic>/<CHANNEL>/<image basename>.png.
std::filesystem::path semantic_mask_path(const nuscenes::Database& db, const nuscenes::SampleData& sd,
                                         const CameraOptions& camera);

struct ColorStats {
  size_t points = 0;          // kept LiDAR points considered (inside the regions)
  size_t images = 0;          // key-frame camera images at the location
  size_t images_used = 0;     // images that won at least one candidate test (decoded)
  size_t occluded_views = 0;  // views rejected by the occlusion test
};

struct LidarsegLayer;
class ColorLayer;
void overlay_semantics(ColorLayer& color, const LidarsegLayer& lidarseg, const std::vector<CellRect>& regions);

class ColorLayer {
 public:
  explicit ColorLayer(double resolution_m = 0.2) : resolution_m_(resolution_m) {}
  const SparseGrid<ColorCell>& cells() const { return cells_; }
  double resolution_m() const { return resolution_m_; }
  size_t rgb_cells() const { return rgb_cells_; }
  size_t semantic_cells() const { return semantic_cells_; }
  const ColorStats& stats() const { return stats_; }

 private:
  friend ColorLayer colorize_scenes(const nuscenes::Database&, const std::vector<int32_t>&, const LidarLayer&,
                                    const std::vector<CellRect>&, const CameraOptions&, int, Progress*);
  friend void overlay_semantics(ColorLayer&, const LidarsegLayer&, const std::vector<CellRect>&);
  double resolution_m_;
  SparseGrid<ColorCell> cells_;
  size_t rgb_cells_ = 0, semantic_cells_ = 0;
  ColorStats stats_;
};

// Colours the kept LiDAR points of `lidar` (from accumulate_location of the same db and
// location) inside `regions` (empty vector = every covered cell). Deterministic: the same
// result at any thread count (`threads` as nsg::parallel_for, 0 = all cores). Throws
// ConfigError (bad options), DataError (no scene at the location, a camera without
// intrinsics or size), IoError naming the first missing semantic mask when
// options.semantic, IoError / ParseError from the JPEG, PNG and sweep readers.
ColorLayer colorize_location(const nuscenes::Database& db, const std::string& location, const LidarLayer& lidar,
                             const std::vector<CellRect>& regions, const CameraOptions& options, int threads);
// The same over a subset of a location's scenes (scene-table rows; `lidar` from
// accumulate_scenes of the same scenes), with `options` already checked. InternalError as accumulate_scenes.
// `progress` (may be null) advances by the images of each chunk processed.
ColorLayer colorize_scenes(const nuscenes::Database& db, const std::vector<int32_t>& scenes, const LidarLayer& lidar,
                           const std::vector<CellRect>& regions, const CameraOptions& options, int threads,
                           Progress* progress = nullptr);

}  // namespace nsg::raster

#include "memory_plan.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>
#include <tuple>
#include <utility>

#include "layer_sources.h"
#include "nsg/core/memory.h"
#include "nsg/core/parallel.h"
#include "nsg/core/strings.h"
#include "nsg/pipeline/config.h"
#include "nsg/raster/color_layer.h"
#include "nsg/raster/lidar_layer.h"
#include "nsg/raster/lidarseg_layer.h"
#include "nsg/raster/vehicle_layer.h"
#include "nsg/tiling/crops.h"

namespace nsg::pipeline {
namespace {

namespace fs = std::filesystem;

using Block = std::pair<int64_t, int64_t>;
constexpr uint64_t kCellsPerBlock = static_cast<uint64_t>(raster::kBlockCells) * raster::kBlockCells;

// Fraction of the blocks within LiDAR range of a pose that returns actually reach: 0.85
// on the synthetic city (2.2 × 1.7 km), 0.69 on the demo world whose map edge is near its
// roads. Real cities are built up to the range limit, like the synthetic city.
constexpr double kReachedBlockFraction = 0.8;
// Covered cells per allocated LiDAR block: 1 − exp(−μ · sweeps per block · (points per
// sweep / 8 000)^κ). Coverage grows with the sweeps' distinct positions more than with
// their points (denser sweeps mostly hit the same near cells again). Fitted on the three
// synthetic worlds: city 2.4 sweeps per block of 8 000 points → 0.31, demo 5.0 → 0.53,
// bench 2.5 of 34 720 points (the real sensor's count) → 0.39.
constexpr double kCoverageRatePerSweep = 0.15;    // μ
constexpr double kCoveragePointsExponent = 0.16;  // κ
constexpr double kCoverageReferencePoints = 8000.0;
// Sweeps whose file size is looked at for the points per sweep (evenly spread).
constexpr size_t kSweepSizeSamples = 256;
// A packed block's bookkeeping besides its cells: occupancy bitmap, row counts, vector
// headers and its node in the block map.
constexpr uint64_t kPackedBlockBytes = 750;
// Reading a map expansion peaks at this many bytes per byte of its JSON file (document,
// records and the graph being built; measured 3.75 on the city's 60 MB map).
constexpr double kMapReadBytesPerFileByte = 3.75;
// Per camera point: its index entry (raster::Target, 32 B) and best view (8 B).
constexpr uint64_t kCameraBytesPerPoint = 40;
// The tiles' share of a location's covered area (0.73 of the covered cells on the demo
// world: random train crops, test crops on a grid, buffers between the regions).
constexpr double kTileShare = 0.75;
// Images in flight: each camera thread decodes one image (RGB at the decode scale, its
// class mask at full size), keeps the candidates and frees the pixels before the next.
constexpr uint64_t kDecodedImageBytesPerPixel = 3;
constexpr uint64_t kMaskBytesPerPixel = 1;
// The lidarseg layer's dense scratch before a fold (256 blocks of 64 KB).
constexpr uint64_t kLidarsegScratchBytes = 16ull << 20;
// The tile stage (the camera stage's buffers are gone by then, so the larger of the two
// counts): the graph's segment index, GeoJSON and manifest, plus one batch of tiles in
// flight (max(8, 4 × threads) tiles, each its 10 B/px of raw layers and about as much
// encoded). Measured: +17 MB on the demo world (256-px tiles), +1 MB on the e2e world
// (128 px); it was a flat 32 MB + 8 MB per thread, which on a small world outweighed
// everything the run really adds (e2e: estimate 1.27× the peak).
constexpr uint64_t kWorkingBytes = 8ull << 20;
constexpr uint64_t kTileBytesPerPixelInFlight = 20;
// The lane graph, its segment index and GeoJSON during the tile stage, per byte of the map
// file, at the default 2 m node spacing; they grow with 2 m / graph.max_spacing_m (the e2e
// world: its 1.0 MB map, peak +21.3 MB at 0.1 m against 2 m).
constexpr double kGraphBytesPerMapByte = 1.1;
// A planned crop: the tiling::Crop, its copy in the split-ordered list and its key.
constexpr double kCropPlanBytes = 2 * sizeof(tiling::Crop) + 64;
// The disc marking runs on cells of at least the range over this (each disc ≤ ~800 cells),
// so estimating takes milliseconds at any resolution: at a fine resolution a cell stands
// for many blocks and a disc's edge cells are counted whole (an overestimate of ≤ 1/8 of
// the range around each disc). At the default resolution a cell is one block.
constexpr double kDiscCellsPerRange = 16.0;
// Byte counts saturate here (an exabyte): far beyond any machine, and no overflow.
constexpr double kMaxBytes = 1e18;

uint64_t bytes_of(double bytes) { return static_cast<uint64_t>(std::clamp(bytes, 0.0, kMaxBytes)); }

// Vehicle boxes are a few metres across: marked on cells of at least this.
constexpr double kVehicleCellM = 1.0;

// The blocks a set of discs reaches, marked on cells of at least `min_cell_m` (and at least
// a block); the count is scaled by the blocks per cell.
struct DiscCells {
  double cell_m;
  double blocks_per_cell;
  std::set<Block> cells;
  DiscCells(double block_m, double min_cell_m)
      : cell_m(std::max(block_m, min_cell_m)), blocks_per_cell((cell_m / block_m) * (cell_m / block_m)) {}
  double blocks() const { return static_cast<double>(cells.size()) * blocks_per_cell; }
};

// Cells within `range_m` of (x, y) (cells of `cell_m` metres).
void mark_disc_blocks(double x, double y, double range_m, double cell_m, std::set<Block>& out) {
  const auto lo = [&](double v) { return static_cast<int64_t>(std::floor((v - range_m) / cell_m)); };
  const auto hi = [&](double v) { return static_cast<int64_t>(std::floor((v + range_m) / cell_m)); };
  for (int64_t by = lo(y); by <= hi(y); ++by) {
    for (int64_t bx = lo(x); bx <= hi(x); ++bx) {
      const double dx = std::max({bx * cell_m - x, 0.0, x - (bx + 1) * cell_m});
      const double dy = std::max({by * cell_m - y, 0.0, y - (by + 1) * cell_m});
      if (dx * dx + dy * dy <= range_m * range_m) out.insert({bx, by});
    }
  }
}

struct LocationFootprint {
  double lidar_blocks = 0;      // union over the location's sweeps
  double max_scene_blocks = 0;  // the largest single scene
  double vehicle_blocks = 0;
  double vehicle_cells = 0.0;  // box footprints, a box seen again in the same place counted once
  size_t images = 0;
  uint64_t max_image_pixels = 0;  // the largest key-frame camera image (full size)
  size_t sweeps = 0;
  size_t key_sweeps = 0;                               // key frames: what lidarseg labels
  double points_per_sweep = kCoverageReferencePoints;  // from a sample of the sweep files' sizes
  uint64_t map_file_bytes = 0;
};

// The mean point count of the `sweeps` (sample_data rows; .pcd.bin holds 5 float32 per
// point) from the file sizes of up to kSweepSizeSamples of them, evenly spread; the
// reference count when none can be read (the LiDAR stage reports missing files by name).
double mean_points_per_sweep(const nuscenes::Database& db, const std::vector<nuscenes::Index>& sweeps) {
  const size_t step = std::max<size_t>(1, sweeps.size() / kSweepSizeSamples);
  double points = 0.0;
  size_t read = 0;
  for (size_t i = 0; i < sweeps.size(); i += step) {
    std::error_code ec;
    const uintmax_t bytes = fs::file_size(db.file_path(db.sample_data[sweeps[i]]), ec);
    if (ec) continue;
    points += static_cast<double>(bytes) / (5 * sizeof(float));
    ++read;
  }
  return read > 0 && points > 0.0 ? points / static_cast<double>(read) : kCoverageReferencePoints;
}

// Covered fraction of the cells of a location's reached blocks by `sweeps` of its sweeps
// (see kCoverageRatePerSweep).
double covered_cell_fraction(const LocationFootprint& f, double reached_blocks, size_t sweeps) {
  if (reached_blocks <= 0.0) return 0.0;
  const double sweeps_per_block = static_cast<double>(sweeps) / reached_blocks;
  const double density = std::pow(f.points_per_sweep / kCoverageReferencePoints, kCoveragePointsExponent);
  return 1.0 - std::exp(-kCoverageRatePerSweep * sweeps_per_block * density);
}

// Vehicle boxes of the scenes: the blocks their footprints reach, and the cells they cover
// (a parked car annotated in every key frame fills the same cells each time).
void add_vehicle_footprint(const nuscenes::Database& db, const std::vector<int>& slot, double block_m,
                           double resolution_m, LocationFootprint& f) {
  DiscCells blocks(block_m, kVehicleCellM);
  std::set<std::tuple<nuscenes::Index, int64_t, int64_t>> seen;  // (instance, 1 m cell of the centre)
  for (const nuscenes::SampleAnnotation& a : db.sample_annotation) {
    if (slot[static_cast<size_t>(db.sample[a.sample].scene)] < 0) continue;
    if (!db.category[a.category].name.starts_with("vehicle.")) continue;
    mark_disc_blocks(a.translation[0], a.translation[1], std::hypot(a.size[0], a.size[1]) / 2, blocks.cell_m,
                     blocks.cells);
    if (seen.insert({a.instance, std::llround(a.translation[0]), std::llround(a.translation[1])}).second)
      f.vehicle_cells += a.size[0] * a.size[1] / (resolution_m * resolution_m);
  }
  f.vehicle_blocks = blocks.blocks();
  f.vehicle_cells = std::min(f.vehicle_cells, f.vehicle_blocks * kCellsPerBlock);
}

LocationFootprint footprint(const nuscenes::Database& db, const std::vector<nuscenes::Index>& scenes,
                            const GenerateConfig& config, const std::string& location) {
  const double block_m = raster::kBlockCells * config.resolution_m;
  const double range_m = config.raster.lidar.max_range_m;
  std::vector<int> slot(db.scene.size(), -1);
  for (size_t i = 0; i < scenes.size(); ++i) slot[static_cast<size_t>(scenes[i])] = static_cast<int>(i);
  const DiscCells empty(block_m, range_m / kDiscCellsPerRange);
  std::vector<DiscCells> per_scene(scenes.size(), empty);
  std::vector<std::pair<double, double>> last(scenes.size(), {1e300, 1e300});
  LocationFootprint f;
  std::vector<nuscenes::Index> sweeps;  // sample_data rows
  for (nuscenes::Index i = 0; i < static_cast<nuscenes::Index>(db.sample_data.size()); ++i) {
    const nuscenes::SampleData& sd = db.sample_data[i];
    const int k = slot[static_cast<size_t>(db.sample[sd.sample].scene)];
    if (k < 0) continue;
    if (sd.modality == nuscenes::Modality::kCamera && sd.is_key_frame) {
      ++f.images;
      f.max_image_pixels = std::max<uint64_t>(f.max_image_pixels, static_cast<uint64_t>(sd.width) * sd.height);
    }
    if (sd.modality != nuscenes::Modality::kLidar || db.channel(sd) != config.raster.lidar_channel) continue;
    sweeps.push_back(i);
    f.key_sweeps += sd.is_key_frame;
    const auto& t = db.ego_pose[sd.ego_pose].translation;
    auto& [lx, ly] = last[static_cast<size_t>(k)];
    DiscCells& scene = per_scene[static_cast<size_t>(k)];
    if (std::hypot(t[0] - lx, t[1] - ly) < 0.25 * scene.cell_m) continue;  // nearby poses mark the same cells
    lx = t[0], ly = t[1];
    mark_disc_blocks(t[0], t[1], range_m, scene.cell_m, scene.cells);
  }
  DiscCells all = empty;
  for (const DiscCells& scene : per_scene) {
    f.max_scene_blocks = std::max(f.max_scene_blocks, scene.blocks());
    all.cells.insert(scene.cells.begin(), scene.cells.end());
  }
  f.lidar_blocks = all.blocks();
  f.sweeps = sweeps.size();
  f.points_per_sweep = mean_points_per_sweep(db, sweeps);
  add_vehicle_footprint(db, slot, block_m, config.resolution_m, f);
  std::error_code ec;  // a missing map fails later with its own message
  const uintmax_t map_size = fs::file_size(fs::path(config.dataroot) / "maps" / "expansion" / (location + ".json"), ec);
  f.map_file_bytes = ec ? 0 : static_cast<uint64_t>(map_size);
  return f;
}

// One camera thread's decoded image and class mask.
uint64_t image_in_flight_bytes(const LocationFootprint& f, const GenerateConfig& config) {
  const raster::CameraOptions& camera = config.raster.camera;
  const uint64_t scale = static_cast<uint64_t>(camera.jpeg_scale_denom) * camera.jpeg_scale_denom;
  return (camera.rgb ? f.max_image_pixels / scale * kDecodedImageBytesPerPixel : 0) +
         (camera.semantic_masks() ? f.max_image_pixels * kMaskBytesPerPixel : 0);
}

// Crops a location's plan can hold: random_total per split (three splits at most), or
// random_per_km2 over the covered area, or a grid over it.
double planned_crops(const GenerateConfig& config, double covered_km2) {
  const tiling::CropOptions& c = config.crops;
  const double crop_km2 = std::pow(c.size_px * config.resolution_m / 1000.0, 2);
  const double random = c.random_total > 0 ? 3.0 * static_cast<double>(c.random_total) : c.random_per_km2 * covered_km2;
  return std::max(random, covered_km2 / crop_km2);
}

// The tile stage: graph, GeoJSON, manifest, the crop plan and one batch of tiles in flight.
uint64_t tile_stage_bytes(const GenerateConfig& config, size_t threads, double crops, uint64_t map_file_bytes) {
  const uint64_t batch = std::max<uint64_t>(8, 4 * threads);
  const uint64_t pixels = static_cast<uint64_t>(config.crops.size_px) * config.crops.size_px;
  const double default_spacing_m = graph::LaneGraphOptions{}.max_spacing_m;
  const double graph =
      kGraphBytesPerMapByte * static_cast<double>(map_file_bytes) * (default_spacing_m / config.graph.max_spacing_m);
  return bytes_of(static_cast<double>(kWorkingBytes + batch * pixels * kTileBytesPerPixelInFlight) +
                  crops * kCropPlanBytes + graph);
}

MemoryEstimate location_estimate(const LocationFootprint& f, const GenerateConfig& config, size_t lanes, size_t threads,
                                 bool cameras, bool lidarseg) {
  MemoryEstimate e;
  const auto blocks_of = [](double blocks, size_t cell_bytes) { return blocks * kCellsPerBlock * cell_bytes; };
  const double reached = kReachedBlockFraction * f.lidar_blocks;
  const double fill = covered_cell_fraction(f, reached, f.sweeps);
  const double block_km2 = std::pow(raster::kBlockCells * config.resolution_m / 1000.0, 2);
  e.map_bytes = bytes_of(kMapReadBytesPerFileByte * static_cast<double>(f.map_file_bytes));
  e.lidar_blocks = bytes_of(reached);
  e.covered_cells = bytes_of(reached * fill * kCellsPerBlock);
  // The finished layers are packed: the covered cells and a little per block.
  e.lidar_bytes = bytes_of(reached * (fill * kCellsPerBlock * sizeof(raster::LidarCell) + kPackedBlockBytes));
  e.vehicle_bytes = bytes_of(f.vehicle_cells * sizeof(raster::VehicleCell) + f.vehicle_blocks * kPackedBlockBytes);
  // Each lane holds one scene's dense LiDAR and vehicle blocks while it accumulates.
  e.scenes_bytes =
      bytes_of(static_cast<double>(lanes) * blocks_of(kReachedBlockFraction * f.max_scene_blocks,
                                                      sizeof(raster::LidarCell) + sizeof(raster::VehicleCell) / 4));
  // The camera stage indexes the covered cells inside the tiles (not known before the
  // crops are planned: kTileShare of them) and writes a dense colour layer over their
  // blocks, packed when it is done (the coloured cells only). The lidarseg layer (packed,
  // key-frame points only) comes after the index is freed and is overlaid block by block
  // onto the packed colour layer: a LiDAR-only release with lidarseg has it too.
  if (cameras && (f.images > 0 || lidarseg)) {
    const double tile_blocks = kTileShare * reached;
    const double key_fill = covered_cell_fraction(f, reached, f.key_sweeps);
    const double kept_fill = f.images > 0 ? fill : key_fill;  // coloured, or labelled only
    const double packed = tile_blocks * (kCellsPerBlock * kept_fill * sizeof(raster::ColorCell) + kPackedBlockBytes);
    double colouring = 0;
    if (f.images > 0)
      colouring = blocks_of(tile_blocks, sizeof(raster::ColorCell)) +
                  tile_blocks * kCellsPerBlock * fill * kCameraBytesPerPoint +
                  static_cast<double>(std::min<uint64_t>(threads, f.images)) *
                      static_cast<double>(image_in_flight_bytes(f, config));
    double labelling = 0;
    if (lidarseg)
      labelling = packed + reached * kCellsPerBlock * key_fill * sizeof(raster::LidarsegCell) + kLidarsegScratchBytes;
    e.colour_bytes = bytes_of(packed);
    e.camera_bytes = bytes_of(std::max({colouring, labelling, packed}));
  }
  e.working_bytes =
      tile_stage_bytes(config, threads, planned_crops(config, reached * fill * block_km2), f.map_file_bytes);
  return e;
}

// A location's estimate over its layer sources (layer_sources.h): one of every scene, or
// under the before-after preset one per side of the date. generate accumulates every
// source's layers before it cuts a tile, so their LiDAR, vehicle and colour layers add up (a
// street both sides drove counts twice); the camera stage's index and images are one
// source's at a time, a thread holds one scene at a time, and the tile stage's plan and
// graph are the location's once.
MemoryEstimate sources_estimate(const nuscenes::Database& db, const std::vector<nuscenes::Index>& scenes,
                                const GenerateConfig& config, int threads, size_t workers, bool cameras, bool lidarseg,
                                const std::string& location) {
  MemoryEstimate sum;
  bool first = true;
  for (const LayerSource& source : layer_sources(db, config, scenes)) {
    if (source.scenes.empty()) continue;
    const LocationFootprint f = footprint(db, source.scenes, config, location);
    const MemoryEstimate e =
        location_estimate(f, config, lane_count(source.scenes.size(), threads), workers, cameras, lidarseg);
    if (first) {
      sum = e;
      first = false;
      continue;
    }
    sum.lidar_blocks += e.lidar_blocks;
    sum.covered_cells += e.covered_cells;
    sum.lidar_bytes += e.lidar_bytes;
    sum.vehicle_bytes += e.vehicle_bytes;
    // Every colour layer so far, beside the larger of the two sources' index and images.
    sum.camera_bytes = sum.colour_bytes + e.colour_bytes +
                       std::max(sum.camera_bytes - sum.colour_bytes, e.camera_bytes - e.colour_bytes);
    sum.colour_bytes += e.colour_bytes;
    sum.scenes_bytes = std::max(sum.scenes_bytes, e.scenes_bytes);
    sum.working_bytes = std::max(sum.working_bytes, e.working_bytes);
  }
  sum.location = location;
  return sum;
}

std::string mb(uint64_t bytes) { return human_bytes(static_cast<double>(bytes)); }

}  // namespace

std::string MemoryEstimate::describe() const {
  return strprintf(
      "%s (at %s: tables and process %s; reading the map %s, then: LiDAR layer %s over ~%llu "
      "blocks, vehicles %s, scenes in progress %s, cameras %s, tiles and graph %s)",
      mb(total()).c_str(), location.c_str(), mb(base_bytes).c_str(), mb(map_bytes).c_str(), mb(lidar_bytes).c_str(),
      static_cast<unsigned long long>(lidar_blocks), mb(vehicle_bytes).c_str(), mb(scenes_bytes).c_str(),
      mb(camera_bytes).c_str(), mb(working_bytes).c_str());
}

std::string MemoryEstimate::plan_details() const {
  return strprintf("location=%s lidar_blocks=%llu covered_cells=%llu packed_block_bytes=%llu", location.c_str(),
                   static_cast<unsigned long long>(lidar_blocks), static_cast<unsigned long long>(covered_cells),
                   static_cast<unsigned long long>(kPackedBlockBytes));
}

std::string MemoryEstimate::how_to_lower() const {
  std::vector<std::pair<uint64_t, std::string>> ways = {
      {lidar_bytes + vehicle_bytes,
       "a smaller region: --locations, or fewer scenes (scenes.exclude) — the LiDAR and vehicle layers grow with "
       "the area the scenes cover"},
      {scenes_bytes, "fewer threads (--threads): each thread holds the dense layers of the scene it accumulates"},
      {camera_bytes, "more processes (--num-shards N, then nsgraph merge): each colours only its own tiles"},
  };
  std::stable_sort(ways.begin(), ways.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::string out;
  for (const auto& [bytes, text] : ways)
    if (bytes > 0) out += "\n  - " + text + " (" + mb(bytes) + ")";
  return out;
}

MemoryEstimate estimate_generate_memory(const nuscenes::Database& db,
                                        const std::map<std::string, std::vector<nuscenes::Index>>& scenes,
                                        const GenerateConfig& config, int threads, bool cameras) {
  const size_t workers = static_cast<size_t>(resolve_threads(threads));
  const bool lidarseg =
      config.raster.camera.semantic && config.raster.camera.semantic_source == raster::SemanticSource::kLidarseg;
  MemoryEstimate peak;
  for (const auto& [location, list] : scenes) {
    if (list.empty()) continue;
    const MemoryEstimate e = sources_estimate(db, list, config, threads, workers, cameras, lidarseg, location);
    if (peak.location.empty() || e.total() > peak.total()) peak = e;
  }
  peak.base_bytes = current_rss_bytes();
  if (peak.location.empty()) peak.working_bytes = tile_stage_bytes(config, workers, 0.0, 0);
  return peak;
}

}  // namespace nsg::pipeline

#include "nsg/raster/color_layer.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

#include "nsg/core/error.h"
#include "nsg/core/files.h"
#include "nsg/core/log.h"
#include "nsg/core/parallel.h"
#include "nsg/raster/accumulate.h"
#include "nsg/raster/raster_options.h"
#include "nsg/geometry/transform.h"
#include "nsg/nuscenes/camera.h"
#include "nsg/nuscenes/database.h"
#include "nsg/nuscenes/lidar.h"
#include "nsg/nuscenes/semantic_mask.h"
#include "occlusion.h"

namespace nsg::raster {

namespace fs = std::filesystem;
using nuscenes::Database;
using nuscenes::Index;

void CameraOptions::validate() const { camera_option_table().check(*this); }

namespace {

using detail::OcclusionSweep;
using detail::ShadowBuffer;
using detail::SweepCache;
using detail::ViewGeometry;

constexpr size_t kChunkImages = 16;  // images in flight at once: bounds memory, not results

// A kept LiDAR point to colour.
struct Target {
  float x, y, z;
  CellIndex cell;
};

// A run of targets: their [begin, end) range and the box around them.
struct TargetRange {
  size_t begin = 0, end = 0;
  float lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};  // x, y, z bounds of the range's targets
};

// A LiDAR block's targets, in parts of kPartCells² cells (the frustum test skips the
// parts outside a camera's view inside a block it sees in part).
constexpr int kPartCells = 16;
struct TargetBlock {
  TargetRange all;
  std::vector<TargetRange> parts;  // the non-empty parts, in order
};

// The targets sorted by LiDAR block, with each block's range and bounds, so an image
// visits only the blocks within its view radius and its camera's frustum.
struct TargetIndex {
  double resolution_m = 0.2;
  std::vector<Target> targets;
  std::map<std::pair<int64_t, int64_t>, TargetBlock> blocks;  // (by, bx) → block
};

// The rects that overlap block (bx, by), so a cell is tested against a few rects, not
// against every tile of the location.
std::vector<CellRect> rects_over_block(const std::vector<CellRect>& regions, int64_t bx, int64_t by) {
  const CellRect block{bx * kBlockCells, by * kBlockCells, (bx + 1) * kBlockCells, (by + 1) * kBlockCells};
  std::vector<CellRect> out;
  for (const CellRect& r : regions)
    if (r.col0 < block.col1 && block.col0 < r.col1 && r.row0 < block.row1 && block.row0 < r.row1) out.push_back(r);
  return out;
}

// Visits the covered cells of `lidar` inside `regions` (empty = all) block by block:
// on_cell(CellIndex, const LidarCell&) for each, then on_block(bx, by).
template <typename OnCell, typename OnBlock>
void visit_targets(const LidarLayer& lidar, const std::vector<CellRect>& regions, OnCell&& on_cell,
                   OnBlock&& on_block) {
  lidar.cells().for_each_block([&](int64_t bx, int64_t by, const LidarCell* cells) {
    const std::vector<CellRect> rects = regions.empty() ? regions : rects_over_block(regions, bx, by);
    if (!regions.empty() && rects.empty()) return;
    for (int r = 0; r < kBlockCells; ++r) {
      for (int c = 0; c < kBlockCells; ++c) {
        const LidarCell& cell = cells[r * kBlockCells + c];
        const CellIndex ci{bx * kBlockCells + c, by * kBlockCells + r};
        if (!cell.has_data()) continue;
        if (!rects.empty() &&
            std::none_of(rects.begin(), rects.end(), [&](const CellRect& x) { return x.contains(ci); }))
          continue;
        on_cell(ci, cell);
      }
    }
    on_block(bx, by);
  });
}

TargetRange bound_range(const std::vector<Target>& targets, size_t begin, size_t end) {
  TargetRange range{begin, end, {}, {}};
  const Target& first = targets[begin];
  for (int a = 0; a < 3; ++a) range.lo[a] = range.hi[a] = (&first.x)[a];
  for (size_t t = begin; t < end; ++t) {
    for (int a = 0; a < 3; ++a) {
      range.lo[a] = std::min(range.lo[a], (&targets[t].x)[a]);
      range.hi[a] = std::max(range.hi[a], (&targets[t].x)[a]);
    }
  }
  return range;
}

// Orders the block's targets [begin, end) part by part and bounds each part. (The order
// of the targets does not show in the layer: each is a cell of its own.)
TargetBlock bound_block(std::vector<Target>& targets, size_t begin) {
  const auto part_of = [](const Target& t) {
    const auto in_block = [](int64_t i) { return static_cast<int>(((i % kBlockCells) + kBlockCells) % kBlockCells); };
    return (in_block(t.cell.row) / kPartCells) * (kBlockCells / kPartCells) + in_block(t.cell.col) / kPartCells;
  };
  std::stable_sort(targets.begin() + static_cast<std::ptrdiff_t>(begin), targets.end(),
                   [&](const Target& a, const Target& b) { return part_of(a) < part_of(b); });
  TargetBlock block{bound_range(targets, begin, targets.size()), {}};
  for (size_t first = begin; first < targets.size();) {
    size_t last = first;
    while (last < targets.size() && part_of(targets[last]) == part_of(targets[first])) ++last;
    block.parts.push_back(bound_range(targets, first, last));
    first = last;
  }
  return block;
}

TargetIndex collect_targets(const LidarLayer& lidar, const std::vector<CellRect>& regions) {
  TargetIndex index;
  index.resolution_m = lidar.resolution_m();
  // Counted first so the index is allocated once at its size: growing it by doubling held
  // up to 1.5× its final size at a reallocation (the camera stage's peak).
  size_t count = 0;
  visit_targets(
      lidar, regions, [&](CellIndex, const LidarCell&) { ++count; }, [](int64_t, int64_t) {});
  index.targets.reserve(count);
  size_t begin = 0;
  visit_targets(
      lidar, regions,
      [&](CellIndex ci, const LidarCell& cell) {
        index.targets.push_back({cell.x, cell.y, cell.z, ci});
      },
      [&](int64_t bx, int64_t by) {
        if (index.targets.size() > begin) index.blocks[{by, bx}] = bound_block(index.targets, begin);
        begin = index.targets.size();
      });
  return index;
}

// One key-frame camera image and what it needs.
struct ImageJob {
  uint32_t order = 0;                 // its place in sample_data order (the tie-break between views)
  Index camera = nuscenes::kNoIndex;  // sample_data row
  Index lidar = nuscenes::kNoIndex;   // the key-frame sweep of the same sample (kNoIndex: none)
  fs::path mask;                      // semantic mask (empty when semantics are off)
};

std::vector<ImageJob> plan_images(const Database& db, const std::vector<Index>& scenes, const CameraOptions& options) {
  std::vector<char> at_location(db.scene.size(), 0);  // the selected scenes
  for (Index s : scenes) at_location[static_cast<size_t>(s)] = 1;
  std::vector<ImageJob> jobs;
  for (Index i = 0; i < static_cast<Index>(db.sample_data.size()); ++i) {
    const nuscenes::SampleData& sd = db.sample_data[i];
    if (sd.modality != nuscenes::Modality::kCamera || !sd.is_key_frame) continue;
    if (!at_location[static_cast<size_t>(db.sample[sd.sample].scene)]) continue;
    ImageJob job{static_cast<uint32_t>(jobs.size()), i, db.key_frame(sd.sample, options.lidar_channel), {}};
    if (options.semantic_masks()) {
      job.mask = semantic_mask_path(db, sd, options);
      // Fail before any work: a release without masks is a configuration question.
      if (!fs::exists(job.mask))
        throw IoError(job.mask.string(), "sample_data " + sd.token.str(),
                      "the semantic class mask of this key-frame image (<semantic_root>/<CHANNEL>/<basename>.png); "
                      "set camera.semantic_root, or disable camera.semantic");
    }
    jobs.push_back(std::move(job));
  }
  // Processed key frame by key frame (sample_data lists a release camera by camera), so
  // the cameras sharing a key-frame sweep run together and the sweep is read once. The
  // order does not show in the layer: Best breaks ties by `order`.
  std::stable_sort(jobs.begin(), jobs.end(), [&](const ImageJob& a, const ImageJob& b) {
    return db.sample_data[a.camera].sample < db.sample_data[b.camera].sample;
  });
  return jobs;
}

// A usable view of a target from one image.
struct Candidate {
  uint32_t target;
  float depth;
  float u, v;
  uint8_t rgb[3];
  uint8_t cls;
};

struct ImageResult {
  std::vector<Candidate> candidates;
  size_t occluded = 0;
};

// The best view so far of each target (depth = +inf: none yet): the closest, and of
// equally close ones the image planned first (`image`: its place in plan_images' list),
// whatever order the images are processed in.
struct Best {
  float depth = std::numeric_limits<float>::infinity();
  uint32_t image = std::numeric_limits<uint32_t>::max();
  uint8_t rgb[3] = {0, 0, 0};
  uint8_t cls = 255;

  bool beaten_by(float other_depth, uint32_t other_image) const {
    return other_depth < depth || (other_depth == depth && other_image < image);
  }
};

// std::lround (halves away from zero) inline, without libm's call, for finite |x| < 2^52:
// there x minus its truncation is exact, so the comparison with one half is too.
inline long round_half_away(double x) {
  const long whole = static_cast<long>(x);  // truncated toward zero
  const double fraction = x - static_cast<double>(whole);
  return whole + static_cast<long>(fraction >= 0.5) - static_cast<long>(fraction <= -0.5);  // no branch to mispredict
}

// Where a candidate's colour is sampled in the image decoded at 1/denom (width × height):
// the top-left of the four pixels blended, and the weights. `denom`: camera.jpeg_scale_denom,
// a power of two (1, 2 or 4), so multiplying by its inverse is exactly the division.
struct ScaledSample {
  int x0, y0;
  double fx, fy;
};
ScaledSample scaled_sample(const Candidate& c, int denom, int width, int height) {
  // Scaled pixel k averages full pixels [k·d, k·d + d − 1]; pixel centres are integer u, v.
  const double off = (denom - 1) / 2.0, inverse = 1.0 / denom;
  const double xs = std::clamp((c.u - off) * inverse, 0.0, width - 1.0);
  const double ys = std::clamp((c.v - off) * inverse, 0.0, height - 1.0);
  const int x0 = static_cast<int>(xs), y0 = static_cast<int>(ys);
  return {x0, y0, xs - x0, ys - y0};
}

void sample_rgb(const nuscenes::RgbImage& img, int denom, Candidate& c) {
  const ScaledSample s = scaled_sample(c, denom, img.width, img.height);
  const int x1 = std::min(s.x0 + 1, img.width - 1), y1 = std::min(s.y0 + 1, img.height - 1);
  const double fx = s.fx, fy = s.fy;
  const uint8_t *p00 = img.at(s.x0, s.y0), *p10 = img.at(x1, s.y0), *p01 = img.at(s.x0, y1), *p11 = img.at(x1, y1);
  for (int k = 0; k < 3; ++k) {
    const double top = p00[k] * (1 - fx) + p10[k] * fx;
    const double bottom = p01[k] * (1 - fx) + p11[k] * fx;
    c.rgb[k] = static_cast<uint8_t>(std::clamp(round_half_away(top * (1 - fy) + bottom * fy), 0L, 255L));
  }
}

// The rows of the image decoded at 1/denom that sample_rgb reads for `candidates`: the
// decoder skips the others (ground points project below the horizon, so about half the
// image is never read).
nuscenes::RowBand sampled_rows(const std::vector<Candidate>& candidates, int denom, int width, int height) {
  nuscenes::RowBand band{height, 0};
  for (const Candidate& c : candidates) {
    const int y0 = scaled_sample(c, denom, width, height).y0;
    band.first = std::min(band.first, y0);
    band.end = std::max(band.end, std::min(y0 + 1, height - 1) + 1);
  }
  return band;
}

// The candidates' indices in image-row order (a counting sort on the full-size row):
// they come in map order, scattered over the image, and the colour and class lookups
// visiting them row by row read the image and the mask front to back instead of missing
// the cache at nearly every candidate. `row_start`: a kept buffer.
void order_by_rows(const std::vector<Candidate>& candidates, int height_px, std::vector<uint32_t>& row_start,
                   std::vector<uint32_t>& order) {
  const auto row_of = [&](const Candidate& c) {
    return static_cast<size_t>(std::clamp(static_cast<int>(c.v), 0, height_px - 1));
  };
  row_start.assign(static_cast<size_t>(height_px) + 1, 0);
  for (const Candidate& c : candidates) ++row_start[row_of(c) + 1];
  for (size_t r = 1; r < row_start.size(); ++r) row_start[r] += row_start[r - 1];
  order.resize(candidates.size());
  for (uint32_t i = 0; i < candidates.size(); ++i) order[row_start[row_of(candidates[i])]++] = i;
}

// A mask may be stored at 1/n of its image's size (sides rounded up, as a scaled JPEG
// decode gives): `segment` writes them at the scale the camera stage samples, so no pixel
// is decoded for nothing. Returns n, or 0 when the mask's size is no such fraction.
constexpr int kMaxMaskScaleDenom = 8;
int mask_scale_denom(const nuscenes::GrayImage& mask, const ViewGeometry& view) {
  for (int n = 1; n <= kMaxMaskScaleDenom; ++n)
    if (mask.width == (view.width + n - 1) / n && mask.height == (view.height + n - 1) / n) return n;
  return 0;
}

// A target's pixel and depth in one image, before the occlusion test.
struct ViewPixel {
  uint32_t target;
  double u, v, depth;
};

// One worker's buffers, kept from image to image: the decoder, the decoded image and mask
// and the shadow cells (≈ 1.8 MB at 1600 × 900 with ½-scale decoding, which fresh
// allocations fault in page by page for every image).
struct ImageScratch {
  nuscenes::JpegDecoder decoder;
  nuscenes::RgbImage image;
  nuscenes::GrayImage mask;
  std::vector<float> shadow_depth;
  std::vector<uint32_t> row_start, order;  // order_by_rows' buffers
  std::vector<ViewPixel> pixels;           // the views before the occlusion test
};

// The views this image could win, before the occlusion test: targets within the view
// radius that project into the image closer than their best view so far. Scans the target
// blocks around the ego whose boxes the camera sees, in block order; fills `pixels`.
void candidate_views(const ViewGeometry& view, const ImageJob& job, const TargetIndex& index,
                     const std::vector<Best>& best, const CameraOptions& options, std::vector<ViewPixel>& pixels) {
  pixels.clear();
  const double r = options.view_radius_m, r2 = r * r;
  const auto visit_block = [&](size_t begin, size_t end) {
    for (size_t t = begin; t < end; ++t) {
      const Target& p = index.targets[t];
      const double dx = p.x - view.ego_x, dy = p.y - view.ego_y;
      if (dx * dx + dy * dy > r2) continue;
      double depth, u, v;
      if (!view.project(p.x, p.y, p.z, options.min_depth_m, depth, u, v) || !view.inside(u, v)) continue;
      if (!best[t].beaten_by(static_cast<float>(depth), job.order)) continue;  // another image saw it better
      pixels.push_back({static_cast<uint32_t>(t), u, v, depth});
    }
  };
  const double block_m = kBlockCells * index.resolution_m;
  const auto block_floor = [&](double m) { return static_cast<int64_t>(std::floor(m / block_m)); };
  for (int64_t by = block_floor(view.ego_y - r); by <= block_floor(view.ego_y + r); ++by) {
    for (int64_t bx = block_floor(view.ego_x - r); bx <= block_floor(view.ego_x + r); ++bx) {
      const auto it = index.blocks.find({by, bx});
      if (it == index.blocks.end()) continue;
      const auto seen = [&](const TargetRange& range) {
        return !view.misses_box(range.lo, range.hi, options.min_depth_m, 1.0, view.width - 1.0, 1.0, view.height - 1.0);
      };
      const TargetBlock& block = it->second;
      if (!seen(block.all)) continue;
      for (const TargetRange& part : block.parts)
        if (seen(part)) visit_block(part.begin, part.end);
    }
  }
}

// The views the sweep's shadows do not hide become the image's candidates; the others are
// counted as occluded.
void occlusion_test(const ViewGeometry& view, const OcclusionSweep* sweep, const CameraOptions& options,
                    const std::vector<ViewPixel>& pixels, std::vector<float>& shadow_depth, ImageResult& out) {
  ShadowBuffer shadows(view, options, shadow_depth);
  if (sweep != nullptr) shadows.add_sweep(*sweep, view);
  for (const ViewPixel& x : pixels) {
    if (shadows.closest(x.u, x.v) < x.depth - options.occlusion_margin_m) {
      ++out.occluded;
      continue;
    }
    out.candidates.push_back(
        {x.target, static_cast<float>(x.depth), static_cast<float>(x.u), static_cast<float>(x.v), {0, 0, 0}, 255});
  }
}

// Decodes the rows of the image the candidates fall on (at the configured scale) and
// samples each candidate's colour, in row order.
void sample_colours(const fs::path& jpeg, const ViewGeometry& view, const CameraOptions& options, ImageScratch& scratch,
                    ImageResult& out) {
  nuscenes::RgbImage& img = scratch.image;
  const auto scale = static_cast<nuscenes::JpegScale>(options.jpeg_scale_denom);
  const int width = nuscenes::scaled_dimension(view.width, scale),
            height = nuscenes::scaled_dimension(view.height, scale);
  scratch.decoder.decode_file_rows(jpeg, scale, sampled_rows(out.candidates, options.jpeg_scale_denom, width, height),
                                   img);
  if (img.width != width || img.height != height)
    throw DataError(
        jpeg.string(), "",
        "an image of the sample_data's size " + std::to_string(view.width) + "×" + std::to_string(view.height));
  for (uint32_t i : scratch.order) sample_rgb(img, options.jpeg_scale_denom, out.candidates[i]);
}

// Reads the image's semantic mask (full size or 1/n of it) and sets each candidate's class.
void sample_classes(const fs::path& mask_file, const ViewGeometry& view, ImageScratch& scratch, ImageResult& out) {
  nuscenes::GrayImage& mask = scratch.mask;
  nuscenes::read_semantic_mask(mask_file, mask);
  const int denom = mask_scale_denom(mask, view);
  if (denom == 0)
    throw DataError(mask_file.string(), "",
                    "a mask of the image's size " + std::to_string(view.width) + "×" + std::to_string(view.height) +
                        " or of 1/n of it (n = 2…" + std::to_string(kMaxMaskScaleDenom) + ", sides rounded up; got " +
                        std::to_string(mask.width) + "×" + std::to_string(mask.height) + ")");
  // The class of the nearest full-size pixel, read from the mask pixel that covers it
  // (mask pixel k covers full pixels [k·n, k·n + n − 1]); n = 1 is the full-size lookup.
  for (uint32_t i : scratch.order) {
    Candidate& c = out.candidates[i];
    const int x = static_cast<int>(round_half_away(c.u)) / denom, y = static_cast<int>(round_half_away(c.v)) / denom;
    c.cls = mask.at(std::min(x, mask.width - 1), std::min(y, mask.height - 1));
  }
}

// `sweep`: the job's key-frame sweep (nullptr: none, no occlusion test).
ImageResult process_image(const Database& db, const ImageJob& job, const OcclusionSweep* sweep,
                          const TargetIndex& index, const std::vector<Best>& best, const CameraOptions& options,
                          ImageScratch& scratch) {
  ImageResult out;
  const ViewGeometry view = detail::view_geometry(db, job.camera);
  // The occlusion test needs the shadow buffer: built only when there is a view to test.
  candidate_views(view, job, index, best, options, scratch.pixels);
  if (scratch.pixels.empty()) return out;
  occlusion_test(view, sweep, options, scratch.pixels, scratch.shadow_depth, out);
  if (out.candidates.empty()) return out;

  order_by_rows(out.candidates, view.height, scratch.row_start, scratch.order);
  const fs::path jpeg = db.file_path(db.sample_data[job.camera]);
  if (options.rgb) sample_colours(jpeg, view, options, scratch, out);
  if (options.semantic_masks()) sample_classes(job.mask, view, scratch, out);
  return out;
}

}  // namespace

fs::path semantic_mask_path(const Database& db, const nuscenes::SampleData& sd, const CameraOptions& camera) {
  const fs::path root = camera.semantic_root.empty() ? db.dataroot() / "semantic" : camera.semantic_root;
  return root / db.channel(sd) / (fs::path(sd.filename).stem().string() + ".png");
}

namespace {
// Whether nuScenes-lidarseg's table exists with records: the test split ships an empty one
// ("[]"), which would give an empty semantic layer without a word. A record is longer than
// 64 bytes, so only a shorter file is read.
bool lidarseg_has_records(const fs::path& table) {
  std::error_code ec;
  if (!fs::is_regular_file(table, ec)) return false;
  const auto bytes = fs::file_size(table, ec);
  if (ec) return false;
  return bytes > 64 || read_file(table).find('{') != std::string::npos;
}
}  // namespace

std::string resolve_semantic_source(CameraOptions& camera, const fs::path& dataroot, const std::string& version) {
  if (!camera.semantic || camera.semantic_source != SemanticSource::kAuto) return "";
  std::error_code ec;
  const fs::path masks = camera.semantic_root.empty() ? dataroot / "semantic" : camera.semantic_root;
  if (fs::is_directory(masks, ec)) {
    camera.semantic_source = SemanticSource::kMasks;
    log::debug("camera.semantic_source auto: masks under " + masks.string());
    return "masks";
  }
  const fs::path lidarseg = dataroot / version / "lidarseg.json";
  if (lidarseg_has_records(lidarseg)) {
    camera.semantic_source = SemanticSource::kLidarseg;
    log::info("camera.semantic_source auto: nuScenes-lidarseg (" + lidarseg.string() + "; no masks under " +
              masks.string() + ")");
    return "lidarseg";
  }
  camera.semantic = false;
  log::info("camera.semantic_source auto: no semantic layer (no masks under " + masks.string() +
            ", no nuScenes-lidarseg records in " + lidarseg.string() +
            "); `nsgraph segment` makes masks, camera.semantic_source=masks|lidarseg requires one");
  return "none";
}

ColorLayer colorize_location(const Database& db, const std::string& location, const LidarLayer& lidar,
                             const std::vector<CellRect>& regions, const CameraOptions& options, int threads) {
  options.validate();
  return colorize_scenes(db, scenes_at(db, location), lidar, regions, options, threads);
}

ColorLayer colorize_scenes(const Database& db, const std::vector<Index>& scenes, const LidarLayer& lidar,
                           const std::vector<CellRect>& regions, const CameraOptions& given, int threads,
                           Progress* progress) {
  // `given` was checked where it was read (config reader, or colorize_location). A source
  // still "auto" (a caller of this library) is made concrete for this release here.
  CameraOptions options = given;
  resolve_semantic_source(options, db.dataroot(), db.version());
  // Both off is a valid generate config (no camera layers) but nothing to colour here.
  if (!options.rgb && !options.semantic_masks())
    throw ConfigError("", "camera.rgb / camera.semantic",
                      "at least one of them enabled (semantics from masks) to colour points");
  check_scene_list(db, scenes);
  const std::vector<ImageJob> jobs = plan_images(db, scenes, options);
  ColorLayer layer(lidar.resolution_m());
  if (jobs.empty()) return layer;  // no camera images (e.g. a LiDAR-only release): nothing to index
  const TargetIndex index = collect_targets(lidar, regions);
  layer.stats_.points = index.targets.size();
  layer.stats_.images = jobs.size();
  if (index.targets.empty()) return layer;

  std::vector<Best> best(index.targets.size());
  std::vector<ImageResult> results;
  SweepCache sweeps;
  std::vector<ImageScratch> scratch(lane_count(kChunkImages, threads));
  for (size_t first = 0; first < jobs.size(); first += kChunkImages) {
    const size_t n = std::min(kChunkImages, jobs.size() - first);
    std::vector<Index> key_frames(n);
    for (size_t k = 0; k < n; ++k) key_frames[k] = jobs[first + k].lidar;
    sweeps.load(db, std::move(key_frames), threads);
    results.assign(n, {});
    parallel_for_lanes(n, threads, [&](size_t lane, size_t k) {
      const ImageJob& job = jobs[first + k];
      results[k] = process_image(db, job, sweeps.find(job.lidar), index, best, options, scratch[lane]);
    });
    if (progress != nullptr) progress->advance(n);
    // A closer view replaces, and of equally close views the one planned first wins, so
    // the result depends neither on the processing order, the chunking nor the thread count.
    for (size_t k = 0; k < n; ++k) {
      const ImageResult& res = results[k];
      const uint32_t image = jobs[first + k].order;
      layer.stats_.occluded_views += res.occluded;
      layer.stats_.images_used += !res.candidates.empty();
      for (const Candidate& c : res.candidates) {
        Best& b = best[c.target];
        if (!b.beaten_by(c.depth, image)) continue;
        b.depth = c.depth;
        b.image = image;
        std::copy(c.rgb, c.rgb + 3, b.rgb);
        b.cls = c.cls;
      }
    }
  }

  const bool masks = options.semantic_masks();
  const uint8_t flags = (options.rgb ? kCoverageRgb : 0) | (masks ? kCoverageSemantic : 0);
  SparseGrid<ColorCell>::Cursor cursor;
  for (size_t t = 0; t < index.targets.size(); ++t) {
    const Best& b = best[t];
    if (!std::isfinite(b.depth)) continue;
    ColorCell& cell = layer.cells_.at(index.targets[t].cell, cursor);
    cell = {b.rgb[0], b.rgb[1], b.rgb[2], masks ? b.cls : uint8_t{255}, flags, b.depth};
    layer.rgb_cells_ += options.rgb;
    layer.semantic_cells_ += masks;
  }
  // Packed, the layer holds the coloured cells only: a tile's LiDAR covers a fraction of
  // its cells, and the layer stays until the tiles are cut (city world with lidarseg: the
  // dense layer was 218 MB of a 990 MB peak).
  layer.cells_.pack_all();
  return layer;
}

}  // namespace nsg::raster

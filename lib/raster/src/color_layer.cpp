#include "nsg/raster/color_layer.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <map>
#include <numbers>
#include <thread>
#include <utility>

#include "nsg/core/error.h"
#include "nsg/core/parallel.h"
#include "nsg/raster/accumulate.h"
#include "nsg/raster/raster_options.h"
#include "nsg/geometry/transform.h"
#include "nsg/nuscenes/camera.h"
#include "nsg/nuscenes/database.h"
#include "nsg/nuscenes/lidar.h"
#include "nsg/nuscenes/semantic_mask.h"

namespace nsg::raster {

namespace fs = std::filesystem;
using nuscenes::Database;
using nuscenes::Index;

void CameraOptions::validate() const { camera_option_table().check(*this); }

namespace {

constexpr int kShadowCellPx = 4;     // occlusion buffer cell (full-resolution pixels)
constexpr size_t kChunkImages = 16;  // images in flight at once: bounds memory, not results

// A kept LiDAR point to colour.
struct Target {
  float x, y, z;
  CellIndex cell;
};

// A LiDAR block's targets: their [begin, end) range and the box around them.
struct TargetBlock {
  size_t begin = 0, end = 0;
  float lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};  // x, y, z bounds of the block's targets
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

TargetBlock bound_block(const std::vector<Target>& targets, size_t begin) {
  TargetBlock block{begin, targets.size(), {}, {}};
  const Target& first = targets[begin];
  for (int a = 0; a < 3; ++a) block.lo[a] = block.hi[a] = (&first.x)[a];
  for (size_t t = begin; t < targets.size(); ++t) {
    for (int a = 0; a < 3; ++a) {
      block.lo[a] = std::min(block.lo[a], (&targets[t].x)[a]);
      block.hi[a] = std::max(block.hi[a], (&targets[t].x)[a]);
    }
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
  const fs::path root = options.semantic_root.empty() ? db.dataroot() / "semantic" : options.semantic_root;
  std::vector<ImageJob> jobs;
  for (Index i = 0; i < static_cast<Index>(db.sample_data.size()); ++i) {
    const nuscenes::SampleData& sd = db.sample_data[i];
    if (sd.modality != nuscenes::Modality::kCamera || !sd.is_key_frame) continue;
    if (!at_location[static_cast<size_t>(db.sample[sd.sample].scene)]) continue;
    ImageJob job{static_cast<uint32_t>(jobs.size()), i, db.key_frame(sd.sample, options.lidar_channel), {}};
    if (options.semantic_masks()) {
      job.mask = root / db.channel(sd) / (fs::path(sd.filename).stem().string() + ".png");
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

// A key-frame sweep as the occlusion test uses it, read, stripped of the ego's roof
// returns (devkit remove_close: not obstacles) and moved to the global frame once for all
// the cameras of its key frame (six on nuScenes).
struct OcclusionSweep {
  // Consecutive points in file order: a spinning LiDAR writes them column by column, so
  // a run is a narrow wedge of azimuth, and a camera skips the runs outside its view.
  static constexpr size_t kRunPoints = 512;
  struct Run {
    float lo[3], hi[3];  // bounds of the run's global x, y, z
  };
  std::vector<nuscenes::LidarPoint> points;  // global frame, roof returns removed
  std::vector<Run> runs;                     // run k: points [k·kRunPoints, (k + 1)·kRunPoints)
  size_t rows_read = 0;                      // the file's rows, before the roof filter
  float max_ring = 0.0f;                     // the largest ring index read
};

// Into `sweep`, whose buffer is reused.
void load_occlusion_sweep(const Database& db, Index lidar, OcclusionSweep& sweep) {
  sweep.max_ring = 0.0f;
  nuscenes::read_lidar_points(db.file_path(db.sample_data[lidar]), sweep.points);
  sweep.rows_read = sweep.points.size();
  for (const nuscenes::LidarPoint& p : sweep.points) sweep.max_ring = std::max(sweep.max_ring, p.ring);
  std::erase_if(sweep.points,
                [](const nuscenes::LidarPoint& p) { return std::abs(p.x) < 1.0f && std::abs(p.y) < 1.0f; });
  nuscenes::sensor_to_global(db, lidar, sweep.points);
  sweep.runs.clear();
  for (size_t first = 0; first < sweep.points.size(); first += OcclusionSweep::kRunPoints) {
    const size_t last = std::min(sweep.points.size(), first + OcclusionSweep::kRunPoints);
    OcclusionSweep::Run run{{sweep.points[first].x, sweep.points[first].y, sweep.points[first].z},
                            {sweep.points[first].x, sweep.points[first].y, sweep.points[first].z}};
    for (size_t i = first; i < last; ++i) {
      const float xyz[3] = {sweep.points[i].x, sweep.points[i].y, sweep.points[i].z};
      for (int a = 0; a < 3; ++a) {
        run.lo[a] = std::min(run.lo[a], xyz[a]);
        run.hi[a] = std::max(run.hi[a], xyz[a]);
      }
    }
    sweep.runs.push_back(run);
  }
}

// Pinhole projection of one image: camera_from_global and K, as the devkit chain does.
struct ViewGeometry {
  geometry::Rigid3 camera_from_global;
  Eigen::Matrix3d k;
  int width = 0, height = 0;
  double ego_x = 0.0, ego_y = 0.0;

  // Depth and pixel of a global point; false when behind the camera plane, or when its
  // depth is not above min_depth_m (then u, v are not computed: most of a sweep lies
  // behind any one camera, and the callers drop those points either way).
  bool project(double x, double y, double z, double min_depth_m, double& depth, double& u, double& v) const {
    const Eigen::Vector3d p = camera_from_global.apply(Eigen::Vector3d(x, y, z));
    depth = p.z();
    if (!(depth > min_depth_m)) return false;
    const Eigen::Vector3d q = k * p;
    if (!(q.z() > 0.0)) return false;
    u = q.x() / q.z();
    v = q.y() / q.z();
    return true;
  }
  bool inside(double u, double v) const { return u > 1.0 && u < width - 1.0 && v > 1.0 && v < height - 1.0; }

  // True when no point of the box [lo, hi] can pass project(min_depth_m) with its pixel
  // inside the window u0 < u < u1, v0 < v < v1 (±inf: no bound): the box lies wholly
  // outside one of the half-spaces depth > min_depth_m, u > u0, … (linear forms of the
  // global point, which any point projecting into the window satisfies). Culls only with a
  // margin far above the rounding of project(), so it never drops a point project() keeps.
  bool misses_box(const float lo[3], const float hi[3], double min_depth_m, double u0, double u1, double v0,
                  double v1) const {
    const Eigen::Matrix3d& r = camera_from_global.rotation;
    const Eigen::Vector3d& t = camera_from_global.translation;
    const Eigen::Matrix3d kr = k * r;
    const Eigen::Vector3d kt = k * t;
    constexpr double kMargin = 1e-3;  // m for the depth form, px·m for the others
    // Whether a·g + b < −margin at every corner of the box (its largest value is).
    const auto below = [&](const Eigen::RowVector3d& a, double b) {
      double most = b;
      for (int i = 0; i < 3; ++i) most += std::max(a(i) * lo[i], a(i) * hi[i]);
      return most < -kMargin;
    };
    // u > u0 ⇔ q.x − u0·q.z > 0 (q.z > 0 for a projected point); u < u1 ⇔ u1·q.z − q.x > 0.
    const auto above_bound = [&](int axis, double bound) {
      return std::isfinite(bound) && below(kr.row(axis) - bound * kr.row(2), kt(axis) - bound * kt.z());
    };
    const auto below_bound = [&](int axis, double bound) {
      return std::isfinite(bound) && below(bound * kr.row(2) - kr.row(axis), bound * kt.z() - kt(axis));
    };
    return below(r.row(2), t.z() - min_depth_m) || above_bound(0, u0) || below_bound(0, u1) || above_bound(1, v0) ||
           below_bound(1, v1);
  }
};

ViewGeometry view_geometry(const Database& db, Index camera) {
  const nuscenes::SampleData& sd = db.sample_data[camera];
  const nuscenes::CalibratedSensor& cs = db.calibrated_sensor[sd.calibrated_sensor];
  if (!cs.camera_intrinsic)
    throw DataError(db.calibrated_sensor.file(), "token " + cs.token.str(),
                    "a camera_intrinsic for camera " + db.channel(sd));
  if (sd.width <= 2 || sd.height <= 2)
    throw DataError(db.sample_data.file(), "token " + sd.token.str(), "the image width and height of a camera record");
  ViewGeometry g;
  g.camera_from_global = nuscenes::global_from_sensor(db, camera).inverse();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) g.k(r, c) = (*cs.camera_intrinsic)[r][c];
  g.width = sd.width;
  g.height = sd.height;
  const nuscenes::EgoPose& ego = db.ego_pose[sd.ego_pose];
  g.ego_x = ego.translation[0];
  g.ego_y = ego.translation[1];
  return g;
}

// The occlusion test as a depth buffer looked up at the point's own pixel. Each LiDAR
// return Q of the key frame casts a "shadow": the image rectangle it may hide, ± side_px
// sideways, from the row where the line of sight passes height_m below Q down to window_px
// further. A point P is occluded when a shadow covering its pixel comes from a return
// closer by more than margin_m. Why this shape: flat ground in front of P lies below P's
// line of sight (up to the few cm by which the kept lowest-z point sits below the surface),
// so it never casts a shadow over P, however dense the rings at a grazing angle; an object
// standing between the camera and P rises above that line and, as rings sample it every
// ≈ 29 px, has a return within window_px above P. Cells are kShadowCellPx² and a return
// writes only the cells its rectangle covers entirely, so a shadow never grows.
class ShadowBuffer {
 public:
  // `storage`: the cells' memory, kept between images by the caller (a fresh buffer per
  // image cost more in page faults than the shadows themselves).
  ShadowBuffer(const ViewGeometry& view, const CameraOptions& options, std::vector<float>& storage)
      : cols_(view.width / kShadowCellPx + 1),
        rows_(view.height / kShadowCellPx + 1),
        side_px_(options.occlusion_side_px),
        window_px_(options.occlusion_window_px),
        height_px_m_(view.k(1, 1) * options.occlusion_height_m),
        depth_(storage) {
    depth_.assign(static_cast<size_t>(cols_) * rows_, std::numeric_limits<float>::infinity());
  }

  void add_sweep(const OcclusionSweep& sweep, const ViewGeometry& view) {
    if (side_px_ == 0.0) side_px_ = column_spacing_px(sweep, view);
    // A return casts only from u ∈ (−side, width + side) and v below the buffer's bottom
    // (its shadow starts below v), so runs of the sweep outside that window are skipped;
    // the shadows are minima, the same in any order.
    const double u0 = -side_px_, u1 = cols_ * kShadowCellPx + side_px_, v1 = rows_ * kShadowCellPx;
    const double inf = std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < sweep.runs.size(); ++k) {
      const OcclusionSweep::Run& run = sweep.runs[k];
      if (view.misses_box(run.lo, run.hi, 0.0, u0, u1, -inf, v1)) continue;
      const size_t first = k * OcclusionSweep::kRunPoints;
      const size_t last = std::min(sweep.points.size(), first + OcclusionSweep::kRunPoints);
      for (size_t i = first; i < last; ++i) {
        const nuscenes::LidarPoint& p = sweep.points[i];
        double depth, u, v;
        if (!view.project(p.x, p.y, p.z, 0.0, depth, u, v)) continue;
        cast(u, v + height_px_m_ / depth, static_cast<float>(depth));
      }
    }
  }
  // Depth of the closest return whose shadow covers pixel (u, v); +inf when none does.
  float closest(double u, double v) const {
    const int c = static_cast<int>(std::floor(u / kShadowCellPx)), r = static_cast<int>(std::floor(v / kShadowCellPx));
    if (c < 0 || r < 0 || c >= cols_ || r >= rows_) return std::numeric_limits<float>::infinity();
    return depth_[static_cast<size_t>(r) * cols_ + c];
  }

 private:
  // The image width of one step between the sweep's columns (a spinning LiDAR returns
  // rings × columns points; 2π / columns in azimuth, f_x px per radian): a shadow as wide
  // closes the gaps between columns on an object, and no wider, so a raised kerb or a
  // pole beside a point does not hide it. Rings = the largest ring index + 1; a sweep
  // without plausible ring indices counts as 32 beams (the nuScenes HDL-32E).
  static double column_spacing_px(const OcclusionSweep& sweep, const ViewGeometry& view) {
    const float max_ring = sweep.max_ring;
    const double rings = max_ring >= 1.0f && max_ring < 128.0f ? std::floor(max_ring) + 1.0 : 32.0;
    const double columns = std::max(1.0, static_cast<double>(sweep.rows_read) / rings);
    return std::min(512.0, view.k(0, 0) * 2.0 * std::numbers::pi / columns);
  }

  // Cells entirely inside [u − side, u + side] × [top, top + window].
  void cast(double u, double top, float depth) {
    const double u0 = u - side_px_, u1 = u + side_px_, v1 = top + window_px_;
    if (!(u1 > 0.0) || !(v1 > 0.0) || !(u0 < cols_ * kShadowCellPx) || !(top < rows_ * kShadowCellPx)) return;
    const int c0 = std::max(0, static_cast<int>(std::ceil(u0 / kShadowCellPx)));
    const int c1 = std::min(cols_, static_cast<int>(std::floor(u1 / kShadowCellPx)));  // exclusive
    const int r0 = std::max(0, static_cast<int>(std::ceil(top / kShadowCellPx)));
    const int r1 = std::min(rows_, static_cast<int>(std::floor(v1 / kShadowCellPx)));
    for (int r = r0; r < r1; ++r) {
      float* row = depth_.data() + static_cast<size_t>(r) * cols_;
      for (int c = c0; c < c1; ++c) row[c] = std::min(row[c], depth);
    }
  }

  int cols_, rows_;
  double side_px_, window_px_, height_px_m_;  // height_px_m_: focal length (px) × occlusion_height_m
  std::vector<float>& depth_;
};

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

void sample_rgb(const nuscenes::RgbImage& img, int denom, Candidate& c) {
  // Scaled pixel k averages full pixels [k·d, k·d + d − 1]; pixel centres are integer u, v.
  const double off = (denom - 1) / 2.0;
  const double xs = std::clamp((c.u - off) / denom, 0.0, img.width - 1.0);
  const double ys = std::clamp((c.v - off) / denom, 0.0, img.height - 1.0);
  const int x0 = static_cast<int>(xs), y0 = static_cast<int>(ys);
  const int x1 = std::min(x0 + 1, img.width - 1), y1 = std::min(y0 + 1, img.height - 1);
  const double fx = xs - x0, fy = ys - y0;
  for (int k = 0; k < 3; ++k) {
    const double top = img.at(x0, y0)[k] * (1 - fx) + img.at(x1, y0)[k] * fx;
    const double bottom = img.at(x0, y1)[k] * (1 - fx) + img.at(x1, y1)[k] * fx;
    c.rgb[k] = static_cast<uint8_t>(std::clamp(round_half_away(top * (1 - fy) + bottom * fy), 0L, 255L));
  }
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

// One worker's buffers, kept from image to image: the decoder, the decoded image and mask
// and the shadow cells (≈ 1.8 MB at 1600 × 900 with ½-scale decoding, which fresh
// allocations fault in page by page for every image).
struct ImageScratch {
  nuscenes::JpegDecoder decoder;
  nuscenes::RgbImage image;
  nuscenes::GrayImage mask;
  std::vector<float> shadow_depth;
  std::vector<uint32_t> row_start, order;  // order_by_rows' buffers
};

// `sweep`: the job's key-frame sweep (nullptr: none, no occlusion test).
ImageResult process_image(const Database& db, const ImageJob& job, const OcclusionSweep* sweep,
                          const TargetIndex& index, const std::vector<Best>& best, const CameraOptions& options,
                          ImageScratch& scratch) {
  ImageResult out;
  const ViewGeometry view = view_geometry(db, job.camera);
  ShadowBuffer shadows(view, options, scratch.shadow_depth);
  if (sweep != nullptr) shadows.add_sweep(*sweep, view);

  const double r = options.view_radius_m, r2 = r * r;
  const auto visit_block = [&](size_t begin, size_t end) {
    for (size_t t = begin; t < end; ++t) {
      const Target& p = index.targets[t];
      const double dx = p.x - view.ego_x, dy = p.y - view.ego_y;
      if (dx * dx + dy * dy > r2) continue;
      double depth, u, v;
      if (!view.project(p.x, p.y, p.z, options.min_depth_m, depth, u, v) || !view.inside(u, v)) continue;
      if (!best[t].beaten_by(static_cast<float>(depth), job.order)) continue;  // another image saw it better
      if (shadows.closest(u, v) < depth - options.occlusion_margin_m) {
        ++out.occluded;
        continue;
      }
      out.candidates.push_back({static_cast<uint32_t>(t),
                                static_cast<float>(depth),
                                static_cast<float>(u),
                                static_cast<float>(v),
                                {0, 0, 0},
                                255});
    }
  };
  const double block_m = kBlockCells * index.resolution_m;
  const auto block_floor = [&](double m) { return static_cast<int64_t>(std::floor(m / block_m)); };
  for (int64_t by = block_floor(view.ego_y - r); by <= block_floor(view.ego_y + r); ++by) {
    for (int64_t bx = block_floor(view.ego_x - r); bx <= block_floor(view.ego_x + r); ++bx) {
      const auto it = index.blocks.find({by, bx});
      if (it == index.blocks.end()) continue;
      const TargetBlock& block = it->second;
      if (!view.misses_box(block.lo, block.hi, options.min_depth_m, 1.0, view.width - 1.0, 1.0, view.height - 1.0))
        visit_block(block.begin, block.end);
    }
  }
  if (out.candidates.empty()) return out;

  order_by_rows(out.candidates, view.height, scratch.row_start, scratch.order);
  const fs::path jpeg = db.file_path(db.sample_data[job.camera]);
  if (options.rgb) {
    nuscenes::RgbImage& img = scratch.image;
    scratch.decoder.decode_file(jpeg, static_cast<nuscenes::JpegScale>(options.jpeg_scale_denom), img);
    const auto scale = static_cast<nuscenes::JpegScale>(options.jpeg_scale_denom);
    if (img.width != nuscenes::scaled_dimension(view.width, scale) ||
        img.height != nuscenes::scaled_dimension(view.height, scale))
      throw DataError(
          jpeg.string(), "",
          "an image of the sample_data's size " + std::to_string(view.width) + "×" + std::to_string(view.height));
    for (uint32_t i : scratch.order) sample_rgb(img, options.jpeg_scale_denom, out.candidates[i]);
  }
  if (options.semantic_masks()) {
    nuscenes::GrayImage& mask = scratch.mask;
    nuscenes::read_semantic_mask(job.mask, mask);
    const int denom = mask_scale_denom(mask, view);
    if (denom == 0)
      throw DataError(job.mask.string(), "",
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
  return out;
}

// The key-frame sweeps of the images in flight: each read once for the cameras of its key
// frame, also when they fall into two chunks (the sweeps of the previous chunk are kept
// for the next). At most one sweep per image of a chunk (≈ 0.7 MB each) is held, in slots
// whose buffers are reused.
class SweepCache {
 public:
  void load(const Database& db, const std::vector<ImageJob>& jobs, size_t first, size_t n, int threads) {
    std::vector<Index> needed;
    for (size_t k = first; k < first + n; ++k)
      if (jobs[k].lidar != nuscenes::kNoIndex) needed.push_back(jobs[k].lidar);
    std::sort(needed.begin(), needed.end());
    needed.erase(std::unique(needed.begin(), needed.end()), needed.end());
    // Slots holding a sweep this chunk does not need are free; the missing sweeps go there.
    std::vector<Slot*> free;
    for (Slot& slot : slots_)
      if (!std::binary_search(needed.begin(), needed.end(), slot.lidar)) free.push_back(&slot);
    std::vector<Slot*> to_load;
    std::vector<Index> loading;
    for (Index lidar : needed) {
      if (find(lidar) != nullptr) continue;
      Slot* slot = nullptr;
      if (!free.empty()) {
        slot = free.back();
        free.pop_back();
      } else {
        slot = &slots_.emplace_back();
      }
      slot->lidar = nuscenes::kNoIndex;  // valid once loaded (a failed load leaves it free)
      to_load.push_back(slot);
      loading.push_back(lidar);
    }
    parallel_for(to_load.size(), threads, [&](size_t i) {
      load_occlusion_sweep(db, loading[i], to_load[i]->sweep);
      to_load[i]->lidar = loading[i];
    });
  }
  const OcclusionSweep* find(Index lidar) const {
    for (const Slot& slot : slots_)
      if (slot.lidar == lidar && lidar != nuscenes::kNoIndex) return &slot.sweep;
    return nullptr;
  }

 private:
  struct Slot {
    Index lidar = nuscenes::kNoIndex;
    OcclusionSweep sweep;
  };
  std::deque<Slot> slots_;  // a deque: slots keep their address as it grows
};

}  // namespace

ColorLayer colorize_location(const Database& db, const std::string& location, const LidarLayer& lidar,
                             const std::vector<CellRect>& regions, const CameraOptions& options, int threads) {
  options.validate();
  return colorize_scenes(db, scenes_at(db, location), lidar, regions, options, threads);
}

ColorLayer colorize_scenes(const Database& db, const std::vector<Index>& scenes, const LidarLayer& lidar,
                           const std::vector<CellRect>& regions, const CameraOptions& options, int threads) {
  // `options` were checked where they were read (config reader, or colorize_location).
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
    sweeps.load(db, jobs, first, n, threads);
    results.assign(n, {});
    parallel_for_lanes(n, threads, [&](size_t lane, size_t k) {
      const ImageJob& job = jobs[first + k];
      results[k] = process_image(db, job, sweeps.find(job.lidar), index, best, options, scratch[lane]);
    });
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
  return layer;
}

}  // namespace nsg::raster

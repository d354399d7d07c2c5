#include "nsg/raster/accumulate.h"

#include <fcntl.h>
#include <unistd.h>

#include <cmath>
#include <mutex>
#include <string_view>
#include <utility>
#include <vector>

#include "nsg/core/error.h"
#include "nsg/core/parallel.h"
#include "nsg/geometry/transform.h"
#include "nsg/nuscenes/database.h"
#include "nsg/nuscenes/detections.h"
#include "nsg/nuscenes/lidar.h"
#include "nsg/raster/raster_options.h"

namespace nsg::raster {

using nuscenes::Database;
using nuscenes::Index;

void RasterOptions::validate() const {
  raster_option_table().check(*this);
  lidar.validate();
}

namespace {

// What one scene contributes: its sweeps and its key frames.
struct SceneWork {
  Index scene = nuscenes::kNoIndex;
  std::vector<Index> sweeps;   // sample_data rows of the LiDAR channel, in table order
  std::vector<Index> samples;  // sample rows, in table order
};

// What one lane (a thread's run of scenes) accumulates.
struct LaneResult {
  explicit LaneResult(double resolution_m) : lidar(resolution_m), vehicles(resolution_m) {}
  LidarLayer lidar;
  VehicleLayer vehicles;
  size_t sweeps = 0, points_read = 0, points_kept = 0, boxes = 0;

  void clear() {
    lidar.clear();
    vehicles.clear();
    sweeps = points_read = points_kept = boxes = 0;
  }
};

// Folds a lane's scene into the shared result.
void fold(const LaneResult& scene, LaneResult& into) {
  into.lidar.merge(scene.lidar);
  into.vehicles.merge(scene.vehicles);
  into.sweeps += scene.sweeps;
  into.points_read += scene.points_read;
  into.points_kept += scene.points_kept;
  into.boxes += scene.boxes;
}

// `scenes` with their sweeps and samples; a single pass over sample_data and sample so the
// cost does not grow with scenes × rows.
std::vector<SceneWork> plan_scenes(const Database& db, const std::vector<Index>& scenes, const std::string& channel) {
  std::vector<int> slot(db.scene.size(), -1);
  std::vector<SceneWork> work;
  for (Index s : scenes) {
    slot[static_cast<size_t>(s)] = static_cast<int>(work.size());
    work.push_back({s, {}, {}});
  }
  for (Index i = 0; i < static_cast<Index>(db.sample.size()); ++i) {
    const int k = slot[static_cast<size_t>(db.sample[i].scene)];
    if (k >= 0) work[static_cast<size_t>(k)].samples.push_back(i);
  }
  for (Index i = 0; i < static_cast<Index>(db.sample_data.size()); ++i) {
    const nuscenes::SampleData& sd = db.sample_data[i];
    if (sd.modality != nuscenes::Modality::kLidar || db.channel(sd) != channel) continue;
    const int k = slot[static_cast<size_t>(db.sample[sd.sample].scene)];
    if (k >= 0) work[static_cast<size_t>(k)].sweeps.push_back(i);
  }
  return work;
}

// The sweep loop reads a sweep in runs of this many rows (80 KB): a run is binned while
// it is still in L2, where a whole sweep (~0.7 MB) would be read back from further out and
// would push the layer's cells out of L2 (measured: 1 024 ≈ 2 048 < 4 096 ≈ 8 192 rows).
// A multiple of the fused kernel's chunk.
constexpr size_t kSweepRunRows = 4096;

// The sweep loop's reusable buffer for a run of the file's rows (capacity kept).
struct SweepBuffers {
  std::vector<nuscenes::LidarPoint> raw;
};

// Asks the kernel to start reading the next sweep while this one is binned (at scale the
// sweeps come from disk); a hint only, so failures are ignored (the read reports them).
void read_ahead(const std::filesystem::path& file) {
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return;
  ::posix_fadvise(fd, 0, 0, POSIX_FADV_WILLNEED);
  ::close(fd);
}

void add_sweep(const Database& db, Index sd_index, const LidarOptions& options, SweepBuffers& buf, LaneResult& out) {
  const nuscenes::SampleData& sd = db.sample_data[sd_index];
  const nuscenes::CalibratedSensor& cs = db.calibrated_sensor[sd.calibrated_sensor];
  const nuscenes::EgoPose& ep = db.ego_pose[sd.ego_pose];
  const geometry::Rigid3 ego_from_sensor = geometry::Rigid3::from_pose(cs.translation, cs.rotation);
  const geometry::Rigid3 global_from_ego = geometry::Rigid3::from_pose(ep.translation, ep.rotation);
  // Finite check, filter (sensor frame, devkit remove_close), sensor → ego → global and
  // lowest-z binning in one pass over each run of rows (LidarLayer::add_sweep: fused
  // AVX2 / AVX-512 kernel where available). A bad value throws after earlier runs were
  // binned: the lane's layers are then dropped with the exception.
  static_assert(sizeof(nuscenes::LidarPoint) == 5 * sizeof(float), "add_sweep takes rows of 5 float32");
  nuscenes::LidarFile file(db.file_path(sd));
  while (!file.done()) {
    const size_t first_row = file.read(buf.raw, kSweepRunRows, nuscenes::LidarFile::Check::kCallerChecks);
    int64_t bad_row = -1;
    out.points_kept += out.lidar.add_sweep(reinterpret_cast<const float*>(buf.raw.data()), buf.raw.size(),
                                           static_cast<int32_t>(first_row), ego_from_sensor, global_from_ego, options,
                                           static_cast<int32_t>(sd_index), LidarLayer::SweepPath::kAuto, &bad_row);
    if (bad_row >= 0) file.fail_not_finite(static_cast<size_t>(bad_row));
  }
  ++out.sweeps;
  out.points_read += file.rows();
}

VehicleBox make_box(const nuscenes::Vec3& translation, const nuscenes::Vec3& size_wlh,
                    const geometry::Quaternion& rotation, double score, int64_t order) {
  VehicleBox box;
  box.center_x_m = translation[0];
  box.center_y_m = translation[1];
  box.yaw_rad = geometry::devkit_yaw(rotation);
  box.width_m = size_wlh[0];
  box.length_m = size_wlh[1];
  box.score = score;
  box.order = order;
  return box;
}

bool is_vehicle_category(std::string_view name) { return name.starts_with("vehicle."); }

void add_annotation_boxes(const Database& db, const SceneWork& work, LaneResult& out) {
  for (Index s : work.samples) {
    const nuscenes::Sample& sample = db.sample[s];
    for (Index a : sample.anns) {
      const nuscenes::SampleAnnotation& ann = db.sample_annotation[a];
      if (!is_vehicle_category(db.category[ann.category].name)) continue;
      out.vehicles.add_box(make_box(ann.translation, ann.size, ann.rotation, 1.0, sample.timestamp_us));
      ++out.boxes;
    }
  }
}

void add_detection_boxes(const Database& db, const nuscenes::DetectionResults& results, double threshold,
                         const SceneWork& work, LaneResult& out) {
  for (Index s : work.samples) {
    const nuscenes::Sample& sample = db.sample[s];
    const Index row = results.find(sample.token);
    if (row == nuscenes::kNoIndex) continue;
    for (const nuscenes::DetectionBox& b : results.samples[static_cast<size_t>(row)].boxes) {
      if (!nuscenes::is_vehicle_class(b.detection_name) || b.detection_score < threshold) continue;
      out.vehicles.add_box(make_box(b.translation, b.size, b.rotation, b.detection_score, sample.timestamp_us));
      ++out.boxes;
    }
  }
}

}  // namespace

void check_scene_list(const Database& db, const std::vector<Index>& scenes) {
  if (scenes.empty()) throw InternalError("", "", "rasterizing an empty list of scenes");
  for (Index s : scenes) {
    if (s < 0 || static_cast<size_t>(s) >= db.scene.size() ||
        db.log[db.scene[s].log].location != db.log[db.scene[scenes.front()].log].location)
      throw InternalError("", "", "rasterizing scenes of different locations (or no scene) into one map frame");
  }
}

std::vector<Index> scenes_at(const Database& db, const std::string& location) {
  std::vector<Index> scenes;
  for (Index s = 0; s < static_cast<Index>(db.scene.size()); ++s)
    if (db.log[db.scene[s].log].location == location) scenes.push_back(s);
  if (scenes.empty())
    throw DataError(db.log.file(), "location " + location, "at least one log (with a scene) at this location");
  return scenes;
}

LocationLayers accumulate_location(const Database& db, const std::string& location, const RasterOptions& options,
                                   int threads) {
  options.validate();
  return accumulate_scenes(db, scenes_at(db, location), options, threads);
}

LocationLayers accumulate_scenes(const Database& db, const std::vector<Index>& scenes, const RasterOptions& options,
                                 int threads, Progress* progress) {
  // `options` were checked where they were read (config reader, or accumulate_location).
  check_scene_list(db, scenes);
  const std::vector<SceneWork> work = plan_scenes(db, scenes, options.lidar_channel);
  nuscenes::DetectionResults detections;
  const bool use_detections = !options.detections_file.empty();
  if (use_detections) {
    detections = nuscenes::read_detections(options.detections_file);
    nuscenes::check_known_samples(detections, db);
  }

  // Scenes go to lanes (one per thread). A lane accumulates one scene into its dense
  // scratch layers (what the sweep kernel writes fastest) and folds them into the shared
  // result under a lock when the scene is done; the fold leaves the result's blocks packed
  // (only the cells holding data). A thread thus holds one scene's dense area on
  // top of the packed result, not most of the city again (scenes of a city overlap), so
  // peak memory follows the covered area whatever the thread count. The folds are
  // associative and commutative (lowest z with tie-breaks; vehicle cells by score and
  // time), so which lane folds what, and when, does not show.
  const double res = options.lidar.resolution_m;
  const size_t lanes = lane_count(work.size(), threads);
  LaneResult shared(res);
  std::vector<LaneResult> scratch;  // layers are move-only
  scratch.reserve(lanes);
  for (size_t k = 0; k < lanes; ++k) scratch.emplace_back(res);
  std::vector<SweepBuffers> buffers(lanes);
  std::mutex fold_mutex;
  parallel_for_lanes(work.size(), threads, [&](size_t lane, size_t k) {
    SweepBuffers& buf = buffers[lane];
    LaneResult& out = scratch[lane];
    const std::vector<Index>& sweeps = work[k].sweeps;
    for (size_t i = 0; i < sweeps.size(); ++i) {
      if (i + 1 < sweeps.size()) read_ahead(db.file_path(db.sample_data[sweeps[i + 1]]));
      add_sweep(db, sweeps[i], options.lidar, buf, out);
      if (progress != nullptr) progress->advance();
    }
    if (use_detections) add_detection_boxes(db, detections, options.detection_score_threshold, work[k], out);
    else add_annotation_boxes(db, work[k], out);
    const std::lock_guard<std::mutex> lock(fold_mutex);
    fold(out, shared);
    out.clear();  // the scene's blocks go; their storage stays for the lane's next scene
  });

  LocationLayers layers{std::move(shared.lidar), std::move(shared.vehicles), {}};
  layers.stats.scenes = work.size();
  layers.stats.sweeps = shared.sweeps;
  layers.stats.points_read = shared.points_read;
  layers.stats.points_kept = shared.points_kept;
  layers.stats.vehicle_boxes = shared.boxes;
  layers.stats.covered_cells = layers.lidar.covered_cells();
  layers.stats.lidar_blocks = layers.lidar.cells().block_count();
  return layers;
}

}  // namespace nsg::raster

#include "occlusion.h"

#include "nsg/core/error.h"
#include "nsg/core/parallel.h"

namespace nsg::raster::detail {

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

void SweepCache::load(const Database& db, std::vector<Index> needed, int threads) {
  needed.erase(std::remove(needed.begin(), needed.end(), nuscenes::kNoIndex), needed.end());
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

const OcclusionSweep* SweepCache::find(Index lidar) const {
  for (const Slot& slot : slots_)
    if (slot.lidar == lidar && lidar != nuscenes::kNoIndex) return &slot.sweep;
  return nullptr;
}

}  // namespace nsg::raster::detail

#pragma once
// LiDAR simulation by ray casting into a SceneSnapshot, plus the ray caster itself
// (shared with camera_sim): ground heightfield, oriented boxes and vertical cylinders,
// with a uniform 2-D grid over the objects built once per snapshot.
#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "nsg/core/rng.h"
#include "nsg/geometry/transform.h"
#include "nsg/synth/scene.h"

namespace nsg::synth {

// What a ray hit (or that it hit nothing: `hit == false`).
struct RayHit {
  bool hit = false;
  double range_m = 0.0;                               // distance along the unit direction
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();  // global frame
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, facing the ray origin side
  enum class Kind : uint8_t { kNone, kGround, kBox, kPole } kind = Kind::kNone;
  GroundMaterial material = GroundMaterial::kTerrain;  // valid for kGround
  SemanticClass cls = SemanticClass::kSkyOther;
  uint8_t lidar_intensity = 0;          // object base intensity (boxes, poles)
  std::array<uint8_t, 3> rgb{0, 0, 0};  // object base colour (boxes, poles)
};

struct RaycastOptions {
  // The ground function's heights must lie in this band; rays are marched only where they
  // are inside it (flat road at 0, sidewalks/curbs ≈ 0.15 m).
  double ground_min_height_m = -0.1;
  double ground_max_height_m = 0.3;
  // Horizontal marching step bounds; the step shrinks so that the ray drops at most
  // `max_drop_per_step_m` per step (finds curb faces and narrow raised strips).
  double min_step_m = 0.05;
  double max_step_m = 1.0;
  double max_drop_per_step_m = 0.05;
  // Uniform grid cell over boxes/poles (0 = chosen from the object density).
  double grid_cell_m = 0.0;
  void validate() const;  // ConfigError naming the bad field
};

// Casts rays into one snapshot. Boxes that contain the ray origin are ignored (a sensor
// mounted inside the ego box sees out). Rays leave the world at `scene.bounds_m`.
// Thread-safe for concurrent cast() calls once built. Keeps a reference to `scene`.
class SceneRaycaster {
 public:
  explicit SceneRaycaster(const SceneSnapshot& scene, const RaycastOptions& options = {});

  // `direction` need not be unit length; ranges are along the normalised direction.
  // Returns the first hit with range in (min_range_m, max_range_m].
  RayHit cast(const Eigen::Vector3d& origin_m, const Eigen::Vector3d& direction, double max_range_m,
              double min_range_m = 1e-6) const;

  // The ground alone (heightfield march), up to max_range_m; for tests and diagnostics.
  RayHit cast_ground(const Eigen::Vector3d& origin_m, const Eigen::Vector3d& unit_dir, double max_range_m) const;

  size_t object_count() const { return objects_.size(); }

 private:
  struct Object {
    bool is_pole = false;
    const SceneBox* box = nullptr;
    const ScenePole* pole = nullptr;
    double cos_yaw = 1.0, sin_yaw = 0.0;
    double z_min = 0.0, z_max = 0.0;
  };
  RayHit cast_objects(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_min, double t_max) const;
  bool intersect(const Object& object, const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_min,
                 double t_max, RayHit& hit) const;
  bool clip_to_bounds(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double& t_min, double& t_max) const;

  const SceneSnapshot& scene_;
  RaycastOptions options_;
  std::vector<Object> objects_;
  double objects_z_min_ = 0.0, objects_z_max_ = 0.0;  // vertical extent of all objects
  // Uniform grid (CSR): cell (ix, iy) holds objects_[cell_items_[cell_start_[c] ..]].
  double grid_x0_ = 0.0, grid_y0_ = 0.0, cell_m_ = 1.0;
  int grid_nx_ = 0, grid_ny_ = 0;
  std::vector<uint32_t> cell_start_;
  std::vector<uint32_t> cell_items_;
};

struct LidarSimOptions {  // defaults = the real 32-beam Velodyne HDL-32E of nuScenes
  int beams = 32;
  double elevation_min_deg = -30.67, elevation_max_deg = 10.67;
  int points_per_sweep = 34720;  // before misses; azimuth steps = points / beams
  double max_range_m = 100.0, range_noise_m = 0.02;
  int roof_points = 8000;  // self-returns from the ego roof within |x|<1,|y|<1 (sensor frame)
  // Added: depth of the simulated roof plane below the sensor (self-returns lie on it).
  double roof_depth_m = 0.35;
  RaycastOptions raycast;  // added: ground band and marching steps
  void validate() const;   // ConfigError naming the bad field
};

// Intensity (0..255) a LiDAR return from ground `material` gets before noise; paint is
// bright (≥ 80), asphalt dark (≈ 10). Exposed so tests/world can use the same thresholds.
double lidar_ground_intensity(GroundMaterial material);

// One sweep: float32 x, y, z, intensity (0..255 integers as float), ring (0..31 as float)
// per point, in the LIDAR_TOP SENSOR frame (x right, y forward, z up: the caller passes
// global_from_sensor), rings interleaved 0..31 per firing like the real sensor (ring 0 =
// lowest elevation); misses (no hit ≤ max range) omitted. The first `roof_points` firings
// of the lowest rings return from the ego roof (plane z = −roof_depth_m, |x|,|y| < 1).
// The spin starts facing +y (forward) and turns clockwise seen from above (towards +x).
std::vector<float> simulate_lidar_sweep(const SceneSnapshot& scene, const geometry::Rigid3& global_from_sensor,
                                        const LidarSimOptions& options, Rng& rng);
// Same with a ray caster built once for the snapshot (reuse it for several sensors).
// `lidarseg_labels`, when given, receives one nuScenes-lidarseg label per returned point
// (lidarseg_label() of what the ray hit; the roof returns are vehicle.ego); the random
// draws, and so the points, are the same with or without it.
std::vector<float> simulate_lidar_sweep(const SceneRaycaster& caster, const geometry::Rigid3& global_from_sensor,
                                        const LidarSimOptions& options, Rng& rng,
                                        std::vector<uint8_t>* lidarseg_labels = nullptr);

// The nuScenes-lidarseg category index (0 noise … 31 vehicle.ego) of a ray hit: the road
// surface (asphalt, paint, crosswalks) flat.driveable_surface, sidewalks and curb tops
// flat.sidewalk, terrain flat.terrain, vegetation static.vegetation, buildings and poles
// static.manmade, cars vehicle.car, trucks and buses vehicle.truck, people
// human.pedestrian.adult, two-wheelers vehicle.bicycle; a miss is noise.
uint8_t lidarseg_label(const RayHit& hit);
inline constexpr uint8_t kLidarsegEgo = 31;

}  // namespace nsg::synth

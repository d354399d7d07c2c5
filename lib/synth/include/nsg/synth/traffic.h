#pragma once
// Who moves where: the ego route along the lane graph and the traffic of one scene
// (moving vehicles following the lane graph, parked cars in parking slots, pedestrians
// walking along sidewalks), each evaluable at any time of the scene.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "nsg/core/rng.h"
#include "nsg/geometry/arcline.h"
#include "nsg/synth/scene.h"
#include "nsg/synth/world.h"

namespace nsg::synth {

// A path along consecutive lanes/connectors, sampled every ≤ 0.5 m.
struct Route {
  std::vector<geometry::Pose2> poses;
  std::vector<double> distance_m;  // cumulative, same size as poses
  std::vector<int> lanes;          // lane indices driven, in order
  double length_m() const { return distance_m.empty() ? 0.0 : distance_m.back(); }
  // Interpolated pose at a distance along the route (clamped to its ends).
  geometry::Pose2 at(double distance_m) const;
};

// A random walk over the lane graph from `start_lane` until `min_length_m` is covered or a
// lane without successors is reached.
Route random_route(const World& world, int start_lane, double min_length_m, Rng& rng);

struct Agent {
  enum class Kind { kMoving, kParked, kPedestrian };
  Kind kind = Kind::kMoving;
  std::string category;  // e.g. "vehicle.car"
  SemanticClass cls = SemanticClass::kCar;
  double length_m = 4.5, width_m = 1.9, height_m = 1.6;
  std::array<uint8_t, 3> rgb{150, 20, 20};
  uint8_t lidar_intensity = 40;
  Route route;           // moving vehicles
  double start_m = 0.0;  // distance along the route (or sidewalk) at t = 0
  double speed_mps = 0.0;
  geometry::Pose2 fixed;  // parked cars; pedestrians: sidewalk start
  double walk_length_m = 0.0;
  double ground_z_m = 0.0;

  geometry::Pose2 pose_at(double t_s) const;
  SceneBox box_at(double t_s) const;  // centre z = ground + height / 2
  bool moving_at(double t_s) const;
};

struct ScenePlan {
  Route ego;
  double ego_start_m = 0.0;
  double ego_speed_mps = 0.0;
  std::vector<Agent> agents;
  geometry::Pose2 ego_pose_at(double t_s) const;
};

// The ego route and traffic of scene `scene_index` lasting `duration_s`.
ScenePlan plan_scene(const World& world, double duration_s, Rng& rng);

}  // namespace nsg::synth

#include "nsg/synth/traffic.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "nsg/core/error.h"

namespace nsg::synth {

using geometry::Pose2;

namespace {
constexpr double kPi = 3.141592653589793;

double lerp_angle(double a, double b, double f) {
  const double d = std::remainder(b - a, 2.0 * kPi);
  return a + d * f;
}
}  // namespace

Pose2 Route::at(double d) const {
  if (poses.empty()) throw InternalError("", "route", "empty route");
  if (d <= 0.0) return poses.front();
  if (d >= distance_m.back()) return poses.back();
  const size_t i = static_cast<size_t>(std::upper_bound(distance_m.begin(), distance_m.end(), d) - distance_m.begin());
  const double d0 = distance_m[i - 1], d1 = distance_m[i];
  const double f = d1 > d0 ? (d - d0) / (d1 - d0) : 0.0;
  const Pose2& a = poses[i - 1];
  const Pose2& b = poses[i];
  return {a.x + (b.x - a.x) * f, a.y + (b.y - a.y) * f, std::remainder(lerp_angle(a.yaw, b.yaw, f), 2.0 * kPi)};
}

Route random_route(const World& world, int start_lane, double min_length_m, Rng& rng) {
  Route r;
  int lane = start_lane;
  for (int guard = 0; guard < 10000; ++guard) {
    r.lanes.push_back(lane);
    const std::vector<Pose2> poly = lane_polyline(world.lanes[static_cast<size_t>(lane)], 0.5);
    for (size_t k = r.poses.empty() ? 0 : 1; k < poly.size(); ++k) {
      const double step =
          r.poses.empty() ? 0.0 : std::hypot(poly[k].x - r.poses.back().x, poly[k].y - r.poses.back().y);
      r.distance_m.push_back((r.distance_m.empty() ? 0.0 : r.distance_m.back()) + step);
      r.poses.push_back(poly[k]);
    }
    const auto& out = world.lanes[static_cast<size_t>(lane)].outgoing;
    if (r.length_m() >= min_length_m || out.empty()) break;
    lane = out[static_cast<size_t>(rng.uniform_int(out.size()))];
  }
  return r;
}

Pose2 Agent::pose_at(double t_s) const {
  switch (kind) {
    case Kind::kParked: return fixed;
    case Kind::kMoving: return route.at(start_m + speed_mps * t_s);
    case Kind::kPedestrian: {
      // Walks back and forth along the sidewalk stretch.
      const double period = 2.0 * walk_length_m;
      double s = std::fmod(start_m + speed_mps * t_s, period);
      if (s < 0) s += period;
      const bool back = s > walk_length_m;
      const double along = back ? period - s : s;
      const double c = std::cos(fixed.yaw), sn = std::sin(fixed.yaw);
      return {fixed.x + c * along, fixed.y + sn * along, back ? std::remainder(fixed.yaw + kPi, 2.0 * kPi) : fixed.yaw};
    }
  }
  return fixed;
}

bool Agent::moving_at(double t_s) const {
  if (kind == Kind::kParked) return false;
  if (kind == Kind::kPedestrian) return speed_mps > 0.0;
  return start_m + speed_mps * t_s < route.length_m();
}

SceneBox Agent::box_at(double t_s) const {
  const Pose2 p = pose_at(t_s);
  SceneBox b;
  b.center_m = {p.x, p.y, ground_z_m + height_m / 2.0};
  b.yaw_rad = p.yaw;
  b.length_m = length_m;
  b.width_m = width_m;
  b.height_m = height_m;
  b.cls = cls;
  b.lidar_intensity = lidar_intensity;
  b.rgb = rgb;
  return b;
}

Pose2 ScenePlan::ego_pose_at(double t_s) const { return ego.at(ego_start_m + ego_speed_mps * t_s); }

namespace {

struct VehicleType {
  const char* category;
  SemanticClass cls;
  double length, width, height;
};
const VehicleType kCar{"vehicle.car", SemanticClass::kCar, 4.6, 1.9, 1.6};
const VehicleType kTruck{"vehicle.truck", SemanticClass::kTruckBus, 7.5, 2.5, 3.2};
const VehicleType kBus{"vehicle.bus.rigid", SemanticClass::kTruckBus, 11.5, 2.9, 3.4};

void set_type(Agent& a, const VehicleType& t, Rng& rng) {
  a.category = t.category;
  a.cls = t.cls;
  const double scale = rng.uniform(0.92, 1.08);
  a.length_m = t.length * scale;
  a.width_m = t.width * rng.uniform(0.95, 1.05);
  a.height_m = t.height * rng.uniform(0.93, 1.07);
  static const std::array<std::array<uint8_t, 3>, 6> kColours = {
      {{180, 20, 20}, {20, 40, 160}, {220, 220, 220}, {30, 30, 30}, {120, 120, 130}, {200, 170, 30}}};
  a.rgb = kColours[rng.uniform_int(kColours.size())];
  a.lidar_intensity = static_cast<uint8_t>(rng.uniform_int(int64_t{20}, int64_t{90}));
}

double dist(const Pose2& a, const Pose2& b) { return std::hypot(a.x - b.x, a.y - b.y); }

// The lanes an agent may start on: lanes, not connectors.
std::vector<int> drivable_lanes(const World& world) {
  std::vector<int> lanes;
  for (size_t i = 0; i < world.lanes.size(); ++i)
    if (!world.lanes[i].is_connector) lanes.push_back(static_cast<int>(i));
  if (lanes.empty()) throw InternalError("", "world", "no lanes to drive on");
  return lanes;
}

// Ego: start on a lane (not a connector) and drive the scene plus a margin.
void plan_ego(const World& world, const std::vector<int>& lanes, double duration_s, Rng& rng, ScenePlan& plan) {
  plan.ego_speed_mps = world.config.scenes.ego_speed_mps * rng.uniform(0.85, 1.15);
  for (int attempt = 0; attempt < 20; ++attempt) {
    const int start = lanes[rng.uniform_int(lanes.size())];
    plan.ego = random_route(world, start, plan.ego_speed_mps * duration_s + 30.0, rng);
    plan.ego_start_m = rng.uniform(0.0, std::min(10.0, world.lanes[static_cast<size_t>(start)].length_m / 2.0));
    if (plan.ego.length_m() >= plan.ego_start_m + plan.ego_speed_mps * duration_s) break;
  }
}

// Moving vehicles on lanes near the ego's start, each at least 14 m from the ego and the
// others at t = 0 (a vehicle without that gap is drawn and dropped).
void add_moving_vehicles(const World& world, const std::vector<int>& lanes, const Pose2& ego0, double near_m,
                         double duration_s, Rng& rng, ScenePlan& plan) {
  std::vector<Pose2> taken = {ego0};
  auto free_at = [&](const Pose2& p, double clearance) {
    for (const Pose2& q : taken)
      if (dist(p, q) < clearance) return false;
    return true;
  };
  std::vector<int> near_lanes;
  for (int i : lanes) {
    const Pose2& s = world.lanes[static_cast<size_t>(i)].paths.front().start_pose;
    if (dist(s, ego0) < near_m) near_lanes.push_back(i);
  }
  if (near_lanes.empty()) near_lanes = lanes;
  std::map<int, double> lane_speed;
  for (int v = 0; v < world.config.traffic.moving_vehicles_per_scene; ++v) {
    Agent a;
    a.kind = Agent::Kind::kMoving;
    const double u = rng.uniform();
    set_type(a, u < 0.8 ? kCar : (u < 0.92 ? kTruck : kBus), rng);
    const int start = near_lanes[rng.uniform_int(near_lanes.size())];
    // One speed per lane (the ego's on its own route), so vehicles sharing a lane keep their
    // gaps instead of driving through each other; there is no car-following model.
    const bool on_ego_route = std::find(plan.ego.lanes.begin(), plan.ego.lanes.end(), start) != plan.ego.lanes.end();
    auto [it, fresh] = lane_speed.try_emplace(start, 0.0);
    if (fresh) it->second = on_ego_route ? plan.ego_speed_mps : rng.uniform(4.0, 11.0);
    a.speed_mps = it->second;
    a.route = random_route(world, start, a.speed_mps * duration_s + 40.0, rng);
    a.start_m = rng.uniform(0.0, world.lanes[static_cast<size_t>(start)].length_m);
    const Pose2 p0 = a.pose_at(0.0);
    if (!free_at(p0, 14.0)) continue;  // keep a gap to the ego and other vehicles at t = 0
    taken.push_back(p0);
    plan.agents.push_back(std::move(a));
  }
}

// Parked cars in a share of the parking slots near the ego.
void add_parked_cars(const World& world, const Pose2& ego0, double near_m, double duration_s, Rng& rng,
                     ScenePlan& plan) {
  const SynthConfig& cfg = world.config;
  for (const Pose2& slot : world.parking_slots) {
    if (dist(slot, ego0) > near_m + cfg.scenes.ego_speed_mps * duration_s) continue;
    if (!rng.bernoulli(cfg.traffic.parked_occupancy)) continue;
    Agent a;
    a.kind = Agent::Kind::kParked;
    set_type(a, rng.bernoulli(0.9) ? kCar : kTruck, rng);
    a.length_m = std::min(a.length_m, cfg.traffic.parked_spacing_m - 0.8);
    a.fixed = {slot.x + rng.uniform(-0.3, 0.3) * std::cos(slot.yaw),
               slot.y + rng.uniform(-0.3, 0.3) * std::sin(slot.yaw), slot.yaw + rng.uniform(-0.03, 0.03)};
    plan.agents.push_back(std::move(a));
  }
}

// Pedestrians on sidewalks near the ego.
void add_pedestrians(const World& world, const Pose2& ego0, double near_m, Rng& rng, ScenePlan& plan) {
  std::vector<size_t> walks;
  for (size_t i = 0; i < world.sidewalks.size(); ++i)
    if (dist(world.sidewalks[i].start, ego0) < near_m + world.sidewalks[i].length_m) walks.push_back(i);
  for (int k = 0; k < world.config.traffic.pedestrians_per_scene && !walks.empty(); ++k) {
    const SidewalkPath& sw = world.sidewalks[walks[rng.uniform_int(walks.size())]];
    Agent a;
    a.kind = Agent::Kind::kPedestrian;
    a.category = "human.pedestrian.adult";
    a.cls = SemanticClass::kPerson;
    a.length_m = rng.uniform(0.55, 0.8);
    a.width_m = rng.uniform(0.55, 0.75);
    a.height_m = rng.uniform(1.55, 1.9);
    a.rgb = {static_cast<uint8_t>(rng.uniform_int(int64_t{40}, int64_t{200})), 60, 90};
    a.lidar_intensity = 25;
    a.fixed = sw.start;
    a.walk_length_m = sw.length_m;
    a.start_m = rng.uniform(0.0, 2.0 * sw.length_m);
    a.speed_mps = rng.uniform(0.9, 1.6);
    a.ground_z_m = 0.15;
    plan.agents.push_back(std::move(a));
  }
}

}  // namespace

// The RNG draws follow the steps' order: ego, moving vehicles, parked cars, pedestrians.
ScenePlan plan_scene(const World& world, double duration_s, Rng& rng) {
  ScenePlan plan;
  const std::vector<int> lanes = drivable_lanes(world);
  plan_ego(world, lanes, duration_s, rng, plan);
  const Pose2 ego0 = plan.ego_pose_at(0.0);
  const double near_m = world.config.traffic.annotation_range_m + 60.0;
  add_moving_vehicles(world, lanes, ego0, near_m, duration_s, rng, plan);
  add_parked_cars(world, ego0, near_m, duration_s, rng, plan);
  add_pedestrians(world, ego0, near_m, rng, plan);
  return plan;
}

}  // namespace nsg::synth

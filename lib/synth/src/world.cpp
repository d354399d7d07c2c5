// The synthetic city (a street grid + ring road, or the organic layout), lanes/connectors,
// ground raster, buildings. Map records are collected by MapBuilder (map_builder.h) while
// the geometry is made. The builder's members live in world_layout_*.cpp (the layout),
// world_roads.cpp and world_connectors.cpp (roads and the map) and world_surface.cpp
// (ground, buildings, poles); this file holds the public functions of world.h, the street
// layout helpers they share, and the build order.
#include "nsg/synth/world.h"

#include <algorithm>
#include <cmath>

#include "nsg/core/error.h"
#include "world_builder.h"

namespace nsg::synth {

using geometry::ArclinePath;
using geometry::ArclineShape;
using geometry::Pose2;
using world_detail::kPi;

// ---------------------------------------------------------------------------------------
// Dubins (CSC words) for lane connectors.

ArclinePath dubins_path(const Pose2& from, const Pose2& to, double radius_m) {
  auto mod2pi = [](double a) {
    double r = std::fmod(a, 2.0 * kPi);
    if (r < 0) r += 2.0 * kPi;
    if (r > 2.0 * kPi - 1e-9) r = 0.0;  // rounding of a zero turn
    return r;
  };
  const double dx = to.x - from.x, dy = to.y - from.y;
  const double d = std::hypot(dx, dy) / radius_m;
  const double theta = mod2pi(std::atan2(dy, dx));
  const double a = mod2pi(from.yaw - theta), b = mod2pi(to.yaw - theta);
  const double sa = std::sin(a), sb = std::sin(b), ca = std::cos(a), cb = std::cos(b);
  const double cab = std::cos(a - b);
  struct Cand {
    ArclineShape shape;
    double t, p, q;
    bool ok;
  };
  std::vector<Cand> c;
  {  // LSL
    const double p2 = 2 + d * d - 2 * cab + 2 * d * (sa - sb);
    const double tmp = std::atan2(cb - ca, d + sa - sb);
    c.push_back({ArclineShape::kLSL, mod2pi(-a + tmp), std::sqrt(std::max(0.0, p2)), mod2pi(b - tmp), p2 >= 0});
  }
  {  // RSR
    const double p2 = 2 + d * d - 2 * cab + 2 * d * (sb - sa);
    const double tmp = std::atan2(ca - cb, d - sa + sb);
    c.push_back({ArclineShape::kRSR, mod2pi(a - tmp), std::sqrt(std::max(0.0, p2)), mod2pi(-b + tmp), p2 >= 0});
  }
  {  // LSR
    const double p2 = -2 + d * d + 2 * cab + 2 * d * (sa + sb);
    const double p = std::sqrt(std::max(0.0, p2));
    const double tmp = std::atan2(-ca - cb, d + sa + sb) - std::atan2(-2.0, p);
    c.push_back({ArclineShape::kLSR, mod2pi(-a + tmp), p, mod2pi(-b + tmp), p2 >= 0});
  }
  {  // RSL
    const double p2 = -2 + d * d + 2 * cab - 2 * d * (sa + sb);
    const double p = std::sqrt(std::max(0.0, p2));
    const double tmp = std::atan2(ca + cb, d - sa - sb) - std::atan2(2.0, p);
    c.push_back({ArclineShape::kRSL, mod2pi(a - tmp), p, mod2pi(b - tmp), p2 >= 0});
  }
  const Cand* best = nullptr;
  for (const Cand& k : c) {
    if (!k.ok) continue;
    if (!best || k.t + k.p + k.q < best->t + best->p + best->q) best = &k;
  }
  if (!best) throw InternalError("", "dubins", "no CSC Dubins path between the lane ends");
  ArclinePath path;
  path.start_pose = from;
  path.shape = best->shape;
  path.radius_m = radius_m;
  path.segment_length_m = {best->t * radius_m, best->p * radius_m, best->q * radius_m};
  path.end_pose = geometry::arcline_pose_at(path, path.length_m());
  return path;
}

std::vector<Pose2> lane_polyline(const LaneInfo& lane, double step_m) {
  std::vector<Pose2> out;
  for (const ArclinePath& path : lane.paths) {
    std::vector<Pose2> poses = geometry::discretize_arcline(path, step_m);
    size_t first = out.empty() ? 0 : 1;
    out.insert(out.end(), poses.begin() + static_cast<long>(first), poses.end());
  }
  return out;
}

// ---------------------------------------------------------------------------------------
// Ground raster.

GroundRaster::GroundRaster(double x0_m, double y0_m, double resolution_m, int width, int height)
    : x0_(x0_m),
      y0_(y0_m),
      res_(resolution_m),
      width_(width),
      height_(height),
      cells_(static_cast<size_t>(width) * height, static_cast<uint8_t>(GroundMaterial::kTerrain)) {}

GroundMaterial GroundRaster::material(double x_m, double y_m) const {
  const double cx = std::floor((x_m - x0_) / res_), cy = std::floor((y_m - y0_) / res_);
  if (!(cx >= 0 && cy >= 0 && cx < width_ && cy < height_)) return GroundMaterial::kTerrain;
  return static_cast<GroundMaterial>(cells_[static_cast<size_t>(cy) * width_ + static_cast<size_t>(cx)]);
}

GroundSample GroundRaster::sample(double x_m, double y_m) const {
  const GroundMaterial m = material(x_m, y_m);
  return {m, material_height_m(m)};
}

double material_height_m(GroundMaterial m) {
  return (m == GroundMaterial::kSidewalk || m == GroundMaterial::kCurbTop) ? 0.15 : 0.0;
}

bool is_drivable_material(GroundMaterial m) {
  return m == GroundMaterial::kAsphalt || m == GroundMaterial::kPaintWhite || m == GroundMaterial::kPaintYellow ||
         m == GroundMaterial::kCrosswalkPaint;
}

GroundFunction World::ground_function() const {
  std::shared_ptr<const GroundRaster> raster = ground;
  return [raster](double x, double y) { return raster->sample(x, y); };
}

SceneSnapshot World::snapshot(std::vector<SceneBox> dynamic_boxes) const {
  SceneSnapshot s;
  s.ground = ground_function();
  s.static_boxes = buildings;
  s.dynamic_boxes = std::move(dynamic_boxes);
  s.poles = poles;
  s.bounds_m = bounds_m;
  return s;
}

namespace world_detail {

// ---------------------------------------------------------------------------------------
// Street layout and piece geometry (shared by the road and the surface builders).

StreetLayout layout_of(const Street& s, bool rht) {
  StreetLayout l;
  const double w = s.lane_w;
  const double park = s.parking ? kParkingWidthM : 0.0;
  // `side` = +1 when the forward lanes are on the left of the reference line.
  if (s.two_way()) {
    const double side = rht ? -1.0 : 1.0;
    for (int k = 0; k < s.n_fwd; ++k) l.fwd_offsets.push_back(side * (k + 0.5) * w);
    for (int k = 0; k < s.n_bwd; ++k) l.bwd_offsets.push_back(-side * (k + 0.5) * w);
    l.fwd_inner = 0.0;
    l.fwd_outer = side * s.n_fwd * w;
    l.bwd_inner = 0.0;
    l.bwd_outer = -side * s.n_bwd * w;
    const double fwd_edge = side * (s.n_fwd * w + park);
    const double bwd_edge = -side * (s.n_bwd * w + park);
    l.left_edge = std::max(fwd_edge, bwd_edge);
    l.right_edge = std::min(fwd_edge, bwd_edge);
  } else {
    const double n = s.n_fwd;
    // Curb side: right for right-hand traffic. Innermost = farthest from it.
    const double curb = rht ? -1.0 : 1.0;
    for (int k = 0; k < s.n_fwd; ++k) l.fwd_offsets.push_back(-curb * (n / 2.0 - k - 0.5) * w);
    l.fwd_inner = -curb * n / 2.0 * w;
    l.fwd_outer = curb * n / 2.0 * w;
    l.left_edge = n / 2.0 * w + park;
    l.right_edge = -(n / 2.0 * w + park);
  }
  return l;
}

// Maps a reference-frame position (s along the piece, d left) to a point, across prims.
Eigen::Vector2d piece_point(const Piece& piece, double s, double d) {
  double rest = s;
  for (size_t i = 0; i < piece.prims.size(); ++i) {
    const Prim& p = piece.prims[i];
    if (rest <= p.length || i + 1 == piece.prims.size()) return prim_point(p, rest, d);
    rest -= p.length;
  }
  return prim_point(piece.prims.back(), rest, d);
}

// Points along the piece at lateral offset d from s0 to s1, evenly spaced ≤ step apart.
std::vector<Eigen::Vector2d> piece_curve(const Piece& piece, double s0, double s1, double d, double step) {
  std::vector<Eigen::Vector2d> out;
  const int n = std::max(1, static_cast<int>(std::ceil((s1 - s0) / step)));
  for (int i = 0; i <= n; ++i) out.push_back(piece_point(piece, s0 + (s1 - s0) * i / n, d));
  return out;
}

WorldBuilder::WorldBuilder(const SynthConfig& config, uint64_t seed)
    : cfg_(config),
      seed_(seed),
      city_(config.city),
      rht_(config.right_hand_traffic()),
      rng_(seed, 0x77'6f'72'6c'64),
      map_(Rng(seed, 0x6d'61'70)) {
  world_.config = config;
}

World WorldBuilder::build() {
  make_layout();
  make_lanes();
  make_connectors();
  make_ground();
  make_map_areas();
  make_buildings_and_poles();
  make_parking_and_sidewalks();
  world_.map_json = map_.to_json(cfg_.map_size_m, world_lanes_json_order());
  return std::move(world_);
}

// lanes first, then connectors (file order of the map's lane / lane_connector layers).
std::vector<MapBuilder::LaneTopology> WorldBuilder::world_lanes_json_order() const {
  std::vector<MapBuilder::LaneTopology> out;
  for (const LaneInfo& lane : world_.lanes) {
    MapBuilder::LaneTopology t;
    t.token = lane.token;
    t.paths = lane.paths;
    for (int o : lane.outgoing) t.outgoing.push_back(world_.lanes[static_cast<size_t>(o)].token);
    for (int i : lane.incoming) t.incoming.push_back(world_.lanes[static_cast<size_t>(i)].token);
    out.push_back(std::move(t));
  }
  return out;
}

}  // namespace world_detail

World build_world(const SynthConfig& config, uint64_t seed) {
  config.validate();
  world_detail::WorldBuilder builder(config, seed);
  return builder.build();  // lanes are all made before the connectors, so lanes come first
}

}  // namespace nsg::synth

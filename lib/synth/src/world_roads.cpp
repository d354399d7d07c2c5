// The road half of the world builder (world_builder.h): the street grid and ring road,
// road pieces between intersections, lanes, lane connectors, ped crossings, stop lines,
// traffic lights and the map's walkways and drivable area. Map records go to MapBuilder in
// the order they are made, so the order of the calls here is part of the output.
#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "map_builder.h"
#include "nsg/core/error.h"
#include "nsg/core/rng.h"
#include "nsg/core/strings.h"
#include "road_geometry.h"
#include "world_builder.h"

namespace nsg::synth::world_detail {

namespace {

ArclinePath straight_path(const Pose2& start, double length, Rng& rng) {
  ArclinePath path;
  path.start_pose = start;
  path.radius_m = kStraightRadiusM;
  // Like real maps: near-straight paths as LSR/RSL with short arcs that cancel.
  const double arc = std::min(rng.uniform(0.0, 0.05), length / 4.0);
  path.shape = rng.bernoulli(0.5) ? ArclineShape::kLSR : ArclineShape::kRSL;
  path.segment_length_m = {arc, length - 2.0 * arc, arc};
  path.end_pose = geometry::arcline_pose_at(path, path.length_m());
  return path;
}

ArclinePath arc_path(const Pose2& start, double length, double curvature) {
  ArclinePath path;
  path.start_pose = start;
  path.radius_m = 1.0 / std::fabs(curvature);
  path.shape = curvature > 0 ? ArclineShape::kLSL : ArclineShape::kRSR;
  path.segment_length_m = {length, 0.0, 0.0};
  path.end_pose = geometry::arcline_pose_at(path, path.length_m());
  return path;
}

Pose2 lane_end_pose(const LaneInfo& lane) {
  const ArclinePath& last = lane.paths.back();
  return geometry::arcline_pose_at(last, last.length_m());
}

double lane_length(const std::vector<ArclinePath>& paths) {
  double l = 0.0;
  for (const auto& p : paths) l += p.length_m();
  return l;
}

}  // namespace

// ---- streets -------------------------------------------------------------------------

Street WorldBuilder::random_street(bool allow_one_way, bool allow_parking) {
  Street s;
  s.lane_w = city_.lane_width_m;
  s.n_fwd = static_cast<int>(rng_.uniform_int(int64_t{1}, int64_t{city_.max_lanes_per_direction}));
  const bool one_way = allow_one_way && rng_.bernoulli(city_.one_way_fraction);
  s.n_bwd = one_way ? 0 : static_cast<int>(rng_.uniform_int(int64_t{1}, int64_t{city_.max_lanes_per_direction}));
  if (one_way && s.n_fwd == 1 && city_.max_lanes_per_direction > 1) s.n_fwd = 2;
  s.parking = allow_parking && rng_.bernoulli(city_.parking_fraction);
  return s;
}

void WorldBuilder::make_streets() {
  const int nx = city_.blocks_x, ny = city_.blocks_y;
  NSG_CHECK(nx >= 2 && ny >= 2, ConfigError, "synth config", "city.blocks_x",
            "at least 2 blocks in x and y (the ring road needs T-junctions on every side)");
  ring_ = static_cast<int>(streets_.size());
  streets_.push_back(random_street(false, rng_.bernoulli(city_.parking_fraction)));
  for (int i = 1; i < nx; ++i) {
    vertical_[i] = static_cast<int>(streets_.size());
    streets_.push_back(random_street(true, true));
  }
  for (int j = 1; j < ny; ++j) {
    horizontal_[j] = static_cast<int>(streets_.size());
    streets_.push_back(random_street(true, true));
  }
  // Intersections: interior crossings and T-junctions on the ring (no node at the corners).
  nodes_.resize(static_cast<size_t>((nx + 1) * (ny + 1)));
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) {
      Intersection& n = nodes_[static_cast<size_t>(node_id(i, j))];
      n.centre = {X(i), Y(j)};
      const bool corner = (i == 0 || i == nx) && (j == 0 || j == ny);
      if (corner) continue;
      const Street& sv = streets_[static_cast<size_t>(i == 0 || i == nx ? ring_ : vertical_.at(i))];
      const Street& sh = streets_[static_cast<size_t>(j == 0 || j == ny ? ring_ : horizontal_.at(j))];
      const StreetLayout lv = layout_of(sv, rht_), lh = layout_of(sh, rht_);
      n.half_m = std::max({lv.left_edge, -lv.right_edge, lh.left_edge, -lh.right_edge}) + 0.5;
      n.arms = (i == 0 || i == nx || j == 0 || j == ny) ? 3 : 4;
    }
  }
}

// ---- pieces --------------------------------------------------------------------------

void WorldBuilder::add_straight_piece(int street, int na, int nb) {
  const Eigen::Vector2d a = nodes_[static_cast<size_t>(na)].centre, b = nodes_[static_cast<size_t>(nb)].centre;
  const Eigen::Vector2d t = (b - a).normalized();
  Piece p;
  p.street = street;
  p.node_a = na;
  p.node_b = nb;
  p.ext_a = ext(na);
  p.ext_b = ext(nb);
  const Eigen::Vector2d s = a + t * p.ext_a;
  p.prims.push_back({{s.x(), s.y(), std::atan2(t.y(), t.x())}, (b - a).norm() - p.ext_a - p.ext_b, 0.0});
  pieces_.push_back(p);
}

// Ring corner: straight from node a to the corner's tangent point, quarter arc left,
// straight to node b.
void WorldBuilder::add_corner_piece(int na, int nb, const Eigen::Vector2d& corner) {
  const double rc = city_.ring_corner_radius_m;
  const Eigen::Vector2d a = nodes_[static_cast<size_t>(na)].centre, b = nodes_[static_cast<size_t>(nb)].centre;
  const Eigen::Vector2d t1 = (corner - a).normalized(), t2 = (b - corner).normalized();
  Piece p;
  p.street = ring_;
  p.node_a = na;
  p.node_b = nb;
  p.ext_a = ext(na);
  p.ext_b = ext(nb);
  const Eigen::Vector2d s = a + t1 * p.ext_a;
  const double yaw1 = std::atan2(t1.y(), t1.x());
  p.prims.push_back({{s.x(), s.y(), yaw1}, (corner - a).norm() - rc - p.ext_a, 0.0});
  const Eigen::Vector2d tp1 = corner - t1 * rc;
  p.prims.push_back({{tp1.x(), tp1.y(), yaw1}, kPi / 2.0 * rc, 1.0 / rc});
  const Eigen::Vector2d tp2 = corner + t2 * rc;
  p.prims.push_back({{tp2.x(), tp2.y(), std::atan2(t2.y(), t2.x())}, (b - corner).norm() - rc - p.ext_b, 0.0});
  pieces_.push_back(p);
}

void WorldBuilder::make_pieces() {
  const int nx = city_.blocks_x, ny = city_.blocks_y;
  for (int i = 1; i < nx; ++i)
    for (int j = 0; j < ny; ++j) add_straight_piece(vertical_.at(i), node_id(i, j), node_id(i, j + 1));
  for (int j = 1; j < ny; ++j)
    for (int i = 0; i < nx; ++i) add_straight_piece(horizontal_.at(j), node_id(i, j), node_id(i + 1, j));
  // The ring, counter-clockwise: bottom (+x), right (+y), top (−x), left (−y).
  for (int i = 1; i + 1 < nx; ++i) add_straight_piece(ring_, node_id(i, 0), node_id(i + 1, 0));
  add_corner_piece(node_id(nx - 1, 0), node_id(nx, 1), {X(nx), Y(0)});
  for (int j = 1; j + 1 < ny; ++j) add_straight_piece(ring_, node_id(nx, j), node_id(nx, j + 1));
  add_corner_piece(node_id(nx, ny - 1), node_id(nx - 1, ny), {X(nx), Y(ny)});
  for (int i = nx - 1; i > 1; --i) add_straight_piece(ring_, node_id(i, ny), node_id(i - 1, ny));
  add_corner_piece(node_id(1, ny), node_id(0, ny - 1), {X(0), Y(ny)});
  for (int j = ny - 1; j > 1; --j) add_straight_piece(ring_, node_id(0, j), node_id(0, j - 1));
  add_corner_piece(node_id(0, 1), node_id(1, 0), {X(0), Y(0)});
}

// ---- lanes ---------------------------------------------------------------------------

std::vector<ArclinePath> WorldBuilder::lane_paths(const Piece& piece, double d, bool forward) {
  std::vector<Prim> prims;
  for (const Prim& p : piece.prims) prims.push_back(offset_prim(p, d));
  if (!forward) {
    std::reverse(prims.begin(), prims.end());
    for (Prim& p : prims) p = reverse_prim(p);
  }
  std::vector<ArclinePath> paths;
  Pose2 start = prims.front().start;
  for (const Prim& p : prims) {
    paths.push_back(p.curvature == 0.0 ? straight_path(start, p.length, rng_) : arc_path(start, p.length, p.curvature));
    start = paths.back().end_pose;
  }
  return paths;
}

void WorldBuilder::make_lanes() {
  for (size_t pi = 0; pi < pieces_.size(); ++pi) {
    const Piece& piece = pieces_[pi];
    const Street& st = streets_[static_cast<size_t>(piece.street)];
    const StreetLayout lay = layout_of(st, rht_);
    const double L = piece.length();
    // Road segment + road blocks (one per direction).
    const std::vector<Eigen::Vector2d> left = piece_curve(piece, 0.0, L, lay.left_edge, 4.0);
    const std::vector<Eigen::Vector2d> right = piece_curve(piece, 0.0, L, lay.right_edge, 4.0);
    const std::string seg = map_.road_segment(band_ring(left, right), false);
    for (int dir = 0; dir < 2; ++dir) {
      const bool forward = dir == 0;
      const std::vector<double>& offs = forward ? lay.fwd_offsets : lay.bwd_offsets;
      if (offs.empty()) {
        piece_block_[pi][dir] = "";
        continue;
      }
      const double inner = forward ? lay.fwd_inner : lay.bwd_inner;
      const double outer_edge = (forward ? lay.fwd_outer : lay.bwd_outer) > inner ? lay.left_edge : lay.right_edge;
      const double lo = std::min(inner, outer_edge), hi = std::max(inner, outer_edge);
      std::vector<Eigen::Vector2d> l = piece_curve(piece, 0.0, L, hi, 4.0), r = piece_curve(piece, 0.0, L, lo, 4.0);
      if (!forward) {
        std::reverse(l.begin(), l.end());
        std::reverse(r.begin(), r.end());
        std::swap(l, r);
      }
      const std::string block = map_.road_block(band_ring(l, r), {r.front(), l.front()}, {r.back(), l.back()}, seg);
      piece_block_[pi][dir] = block;
      for (size_t k = 0; k < offs.size(); ++k) {
        LaneBuild lb;
        lb.piece = static_cast<int>(pi);
        lb.forward = forward;
        lb.index = static_cast<int>(k);
        lb.group_size = static_cast<int>(offs.size());
        lb.start_node = forward ? piece.node_a : piece.node_b;
        lb.end_node = forward ? piece.node_b : piece.node_a;
        lb.offset_ref = offs[k];
        lb.road_block = block;
        LaneInfo lane;
        lane.paths = lane_paths(piece, offs[k], forward);
        lane.length_m = lane_length(lane.paths);
        lane.offset_from_centre_m = forward ? offs[k] : -offs[k];
        lane.two_way_road = st.two_way();
        add_lane_record(piece, st, lay, lb, lane);
        builds_.push_back(lb);
        world_.lanes.push_back(std::move(lane));
      }
    }
    // Dividers: road divider on the centre line of two-way streets; lane dividers between
    // same-direction lanes.
    if (st.two_way()) map_.road_divider(piece_curve(piece, 0.0, L, 0.0, 4.0), seg);
    for (int dir = 0; dir < 2; ++dir) {
      const std::vector<double>& offs = dir == 0 ? lay.fwd_offsets : lay.bwd_offsets;
      for (size_t k = 1; k < offs.size(); ++k) {
        map_.lane_divider(piece_curve(piece, 0.0, L, (offs[k] + offs[k - 1]) / 2.0, 4.0), "SINGLE_DASHED_WHITE");
      }
    }
  }
}

// The lane polygon with its divider segments and edge lines.
void WorldBuilder::add_lane_record(const Piece& piece, const Street& st, const StreetLayout& lay, const LaneBuild& lb,
                                   LaneInfo& lane) {
  const double w = st.lane_w;
  const double L = piece.length();
  // Boundaries in the lane's own direction: left = +w/2 of its own frame.
  const double sgn = lb.forward ? 1.0 : -1.0;
  const double d_left = lb.offset_ref + sgn * w / 2.0, d_right = lb.offset_ref - sgn * w / 2.0;
  std::vector<Eigen::Vector2d> l = piece_curve(piece, 0.0, L, d_left, 4.0);
  std::vector<Eigen::Vector2d> r = piece_curve(piece, 0.0, L, d_right, 4.0);
  if (!lb.forward) {
    std::reverse(l.begin(), l.end());
    std::reverse(r.begin(), r.end());
  }
  auto boundary_type = [&](double d) -> std::string {
    if (st.two_way() && std::fabs(d) < 1e-6) return rht_ ? "DOUBLE_SOLID_YELLOW" : "DOUBLE_SOLID_WHITE";
    const double edge_span = std::max(std::fabs(lay.fwd_outer), std::fabs(lay.bwd_outer));
    if (std::fabs(std::fabs(d) - edge_span) < 1e-6 || std::fabs(d - lay.fwd_outer) < 1e-6 ||
        std::fabs(d - lay.fwd_inner) < 1e-6 || std::fabs(d - lay.bwd_outer) < 1e-6)
      return st.parking ? "SINGLE_SOLID_WHITE" : "NIL";
    return "SINGLE_DASHED_WHITE";
  };
  lane.token = map_.lane(l, r, boundary_type(d_left), boundary_type(d_right));
}

// ---- connectors ----------------------------------------------------------------------

void WorldBuilder::make_connectors() {
  const size_t n_lanes = world_.lanes.size();
  std::map<int, std::vector<int>> in_by_node, out_by_node;
  for (size_t i = 0; i < n_lanes; ++i) {
    in_by_node[builds_[i].end_node].push_back(static_cast<int>(i));
    out_by_node[builds_[i].start_node].push_back(static_cast<int>(i));
  }
  for (size_t ni = 0; ni < nodes_.size(); ++ni) {
    Intersection& node = nodes_[ni];
    if (node.arms == 0) continue;
    const double h = node.half_m;
    std::vector<Eigen::Vector2d> square = {node.centre + Eigen::Vector2d(-h, -h), node.centre + Eigen::Vector2d(h, -h),
                                           node.centre + Eigen::Vector2d(h, h), node.centre + Eigen::Vector2d(-h, h)};
    node.segment_token = map_.road_segment(square, true);
    const std::vector<int>& ins = in_by_node[static_cast<int>(ni)];
    const std::vector<int>& outs = out_by_node[static_cast<int>(ni)];
    for (int a : ins) {
      const Pose2 A = lane_end_pose(world_.lanes[static_cast<size_t>(a)]);
      const LaneBuild& la = builds_[static_cast<size_t>(a)];
      std::vector<int> moves;  // out lanes
      std::vector<int> fallback;
      for (int b : outs) {
        const LaneBuild& lb = builds_[static_cast<size_t>(b)];
        if (lb.piece == la.piece) continue;  // no U-turns
        const Pose2& B = world_.lanes[static_cast<size_t>(b)].paths.front().start_pose;
        const double turn = geometry::wrap_angle_devkit(B.yaw - A.yaw);
        const bool straight = std::fabs(turn) < kPi / 4.0;
        const bool near_turn = !straight && ((turn < 0) == rht_);
        bool take = false;
        if (straight) take = lb.index == std::min(la.index, lb.group_size - 1);
        else if (near_turn) take = la.index == la.group_size - 1 && lb.index == lb.group_size - 1;
        else take = la.index == 0 && lb.index == 0;
        if (take) moves.push_back(b);
        else if (lb.index == (near_turn ? lb.group_size - 1 : 0)) fallback.push_back(b);
      }
      if (moves.empty() && !fallback.empty()) moves.push_back(fallback.front());
      for (int b : moves) add_connector(a, b);
    }
    // An outgoing lane nobody reaches (more lanes out than in) forks off the incoming
    // lane heading the same way that is nearest to it, else off any other arm.
    for (int b : outs) {
      if (!world_.lanes[static_cast<size_t>(b)].incoming.empty()) continue;
      const LaneBuild& lb = builds_[static_cast<size_t>(b)];
      const Pose2& B = world_.lanes[static_cast<size_t>(b)].paths.front().start_pose;
      int best = -1;
      double best_cost = 1e300;
      for (int a : ins) {
        const LaneBuild& la = builds_[static_cast<size_t>(a)];
        if (la.piece == lb.piece) continue;
        const double turn =
            std::fabs(geometry::wrap_angle_devkit(B.yaw - lane_end_pose(world_.lanes[static_cast<size_t>(a)]).yaw));
        const double cost = (turn < kPi / 4.0 ? 0.0 : 100.0) + std::abs(la.index - lb.index);
        if (cost < best_cost) best_cost = cost, best = a;
      }
      if (best >= 0) add_connector(best, b);
    }
    make_crossings(static_cast<int>(ni));
  }
}

void WorldBuilder::add_connector(int a, int b) {
  const Pose2 A = lane_end_pose(world_.lanes[static_cast<size_t>(a)]);
  const Pose2 B = world_.lanes[static_cast<size_t>(b)].paths.front().start_pose;
  const double c = std::cos(A.yaw), s = std::sin(A.yaw);
  const double fx = c * (B.x - A.x) + s * (B.y - A.y), ly = -s * (B.x - A.x) + c * (B.y - A.y);
  const double turn = geometry::wrap_angle_devkit(B.yaw - A.yaw);
  const double radius =
      std::fabs(turn) < kPi / 4.0 ? kStraightRadiusM : std::max(2.0, 0.98 * std::min(std::fabs(fx), std::fabs(ly)));
  ArclinePath path = dubins_path(A, B, radius);
  const Pose2 end = geometry::arcline_pose_at(path, path.length_m());
  if (std::hypot(end.x - B.x, end.y - B.y) > 1e-3)
    throw InternalError("", "lane connector",
                        strprintf("Dubins end misses the lane start by %g m", std::hypot(end.x - B.x, end.y - B.y)));
  LaneInfo conn;
  conn.is_connector = true;
  conn.paths = {path};
  conn.length_m = path.length_m();
  // Placeholder polygon like real connectors: the centreline buffered by half a lane.
  std::vector<Eigen::Vector2d> l, r;
  for (const Pose2& p : geometry::discretize_arcline(path, 2.0)) {
    const Eigen::Vector2d n(-std::sin(p.yaw), std::cos(p.yaw));
    l.push_back(Eigen::Vector2d(p.x, p.y) + n * 1.5);
    r.push_back(Eigen::Vector2d(p.x, p.y) - n * 1.5);
  }
  conn.token = map_.lane_connector(band_ring(l, r));
  const int ci = static_cast<int>(world_.lanes.size());
  world_.lanes.push_back(std::move(conn));
  world_.lanes[static_cast<size_t>(a)].outgoing.push_back(ci);
  world_.lanes[static_cast<size_t>(ci)].incoming.push_back(a);
  world_.lanes[static_cast<size_t>(ci)].outgoing.push_back(b);
  world_.lanes[static_cast<size_t>(b)].incoming.push_back(ci);
}

// Ped crossings on every arm, stop lines before them, traffic lights at 4-way crossings.
void WorldBuilder::make_crossings(int ni) {
  const Intersection& node = nodes_[static_cast<size_t>(ni)];
  for (size_t pi = 0; pi < pieces_.size(); ++pi) {
    const Piece& piece = pieces_[pi];
    for (int end = 0; end < 2; ++end) {
      if ((end == 0 ? piece.node_a : piece.node_b) != ni) continue;
      const StreetLayout lay = layout_of(streets_[static_cast<size_t>(piece.street)], rht_);
      const double L = piece.length();
      // Crosswalk zone in piece coordinates.
      const double s0 = end == 0 ? -kCrosswalkDepthM + 0.5 : L + 0.5;
      const double s1 = end == 0 ? -0.5 : L + kCrosswalkDepthM - 0.5;
      const Prim& prim = end == 0 ? piece.prims.front() : piece.prims.back();
      const double base = end == 0 ? 0.0 : L - prim.length;
      auto pt = [&](double s, double d) { return prim_point(prim, s - base, d); };
      const std::string pc = map_.ped_crossing(
          {pt(s0, lay.right_edge), pt(s1, lay.right_edge), pt(s1, lay.left_edge), pt(s0, lay.left_edge)},
          node.segment_token);
      // Incoming direction at this end: forward lanes end at node_b, backward at node_a.
      const int dir = end == 1 ? 0 : 1;
      const std::string& block = piece_block_[pi][dir];
      if (block.empty()) continue;
      const double in_lo = dir == 0 ? std::min(lay.fwd_inner, lay.fwd_outer) : std::min(lay.bwd_inner, lay.bwd_outer);
      const double in_hi = dir == 0 ? std::max(lay.fwd_inner, lay.fwd_outer) : std::max(lay.bwd_inner, lay.bwd_outer);
      const double t0 = end == 1 ? L - 0.5 : 0.0, t1 = end == 1 ? L : 0.5;
      std::vector<std::string> lights;
      if (node.arms == 4) {
        const double curb = dir == 0 ? (lay.fwd_outer > lay.fwd_inner ? lay.left_edge : lay.right_edge)
                                     : (lay.bwd_outer > lay.bwd_inner ? lay.left_edge : lay.right_edge);
        const double sl = end == 1 ? L + kCrosswalkDepthM : -kCrosswalkDepthM;
        const Eigen::Vector2d p0 = pt(sl, curb), p1 = pt(sl, curb * 0.5);
        const double yaw = end == 1 ? prim.start.yaw + kPi : prim.start.yaw;  // faces the traffic
        lights.push_back(map_.traffic_light({p0, p1}, block, opposite_blocks(ni, static_cast<int>(pi)), yaw));
        world_.poles.push_back(ScenePole{p0, 0.15, 5.5, SemanticClass::kPoleSign, 70, {60, 60, 60}});
      }
      map_.stop_line({pt(t0, in_lo), pt(t1, in_lo), pt(t1, in_hi), pt(t0, in_hi)},
                     lights.empty() ? "PED_CROSSING" : "TRAFFIC_LIGHT",
                     lights.empty() ? std::vector<std::string>{pc} : std::vector<std::string>{}, lights, block);
    }
  }
}

std::vector<std::string> WorldBuilder::opposite_blocks(int ni, int from_piece) {
  std::vector<std::string> out;
  for (size_t pi = 0; pi < pieces_.size(); ++pi) {
    if (static_cast<int>(pi) == from_piece) continue;
    const Piece& p = pieces_[pi];
    if (p.node_a == ni && !piece_block_[pi][0].empty()) out.push_back(piece_block_[pi][0]);
    if (p.node_b == ni && !piece_block_[pi][1].empty()) out.push_back(piece_block_[pi][1]);
  }
  return out;
}

// ---- other map areas -----------------------------------------------------------------

void WorldBuilder::make_map_areas() {
  // Walkways along every piece side; drivable area = all road segment outlines.
  std::vector<std::string> drivable;
  for (size_t pi = 0; pi < pieces_.size(); ++pi) {
    const Piece& piece = pieces_[pi];
    const StreetLayout lay = layout_of(streets_[static_cast<size_t>(piece.street)], rht_);
    const double L = piece.length();
    const double sw = city_.sidewalk_width_m;
    map_.walkway(
        band_ring(piece_curve(piece, 0.0, L, lay.left_edge + sw, 4.0), piece_curve(piece, 0.0, L, lay.left_edge, 4.0)));
    map_.walkway(band_ring(piece_curve(piece, 0.0, L, lay.right_edge, 4.0),
                           piece_curve(piece, 0.0, L, lay.right_edge - sw, 4.0)));
    drivable.push_back(map_.polygon(band_ring(piece_curve(piece, -piece.ext_a, L + piece.ext_b, lay.left_edge, 4.0),
                                              piece_curve(piece, -piece.ext_a, L + piece.ext_b, lay.right_edge, 4.0))));
  }
  map_.drivable_area(drivable);
}

}  // namespace nsg::synth::world_detail

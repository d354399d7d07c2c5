// The road half of the world builder (world_builder.h): over the layout's road pieces,
// lanes, ped crossings, stop lines, traffic lights and the map's walkways and drivable area. Map records go to
// MapBuilder in the order they are made, so the order of the calls here is part of the output.
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

double lane_length(const std::vector<ArclinePath>& paths) {
  double l = 0.0;
  for (const auto& p : paths) l += p.length_m();
  return l;
}

}  // namespace

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
    piece_segment_.push_back(seg);
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
        lb.group_pocket = forward && st.pocket;
        lb.pocket = lb.group_pocket && k == 0;
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
        const double d = (offs[k] + offs[k - 1]) / 2.0;
        dividers_.push_back({map_.lane_divider(piece_curve(piece, 0.0, L, d, 4.0), "SINGLE_DASHED_WHITE"),
                             static_cast<int>(pi), dir == 0, static_cast<int>(offs.size()), d});
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

// Ped crossings on every arm (roundabout rings excepted), stop lines before them, traffic
// lights at signalized junctions.
void WorldBuilder::make_crossings(int ni) {
  const Intersection& node = nodes_[static_cast<size_t>(ni)];
  for (size_t pi = 0; pi < pieces_.size(); ++pi) {
    const Piece& piece = pieces_[pi];
    for (int end = 0; end < 2; ++end) {
      if ((end == 0 ? piece.node_a : piece.node_b) != ni || !(end == 0 ? piece.cross_a : piece.cross_b)) continue;
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
      if (node.signalized) {
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
  for (const Intersection& node : nodes_)
    if (node.own_area) drivable.push_back(map_.polygon(node.area));
  map_.drivable_area(drivable);
}

}  // namespace nsg::synth::world_detail

// The lane connectors of the world builder (world_builder.h): at every node, incoming lane
// ends are joined to outgoing lane starts by Dubins CSC arclines. Junctions join lanes by
// turn class (straight, near turn, far turn) and lane index; transitions (no junction area:
// lane drops, added lanes, pockets opening, ramps) join each lane to its nearest
// continuation and fork the lanes nobody reaches. Map records follow the call order.
#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

#include "map_builder.h"
#include "nsg/core/error.h"
#include "nsg/core/strings.h"
#include "road_geometry.h"
#include "world_builder.h"

namespace nsg::synth::world_detail {

namespace {

// No U-turns, not even between the two carriageways of a divided road.
constexpr double kMaxTurnRad = 150.0 * kPi / 180.0;
// Transitions join lanes heading (nearly) the same way only.
constexpr double kMaxTransitionTurnRad = kPi / 3.0;

Pose2 lane_end_pose(const LaneInfo& lane) {
  const ArclinePath& last = lane.paths.back();
  return geometry::arcline_pose_at(last, last.length_m());
}

// Signed lateral offset of `to` in the frame of `from` (left positive).
double lateral_m(const Pose2& from, const Pose2& to) {
  return -std::sin(from.yaw) * (to.x - from.x) + std::cos(from.yaw) * (to.y - from.y);
}

// A CSC path that turns no more than the lane ends ask for plus a quarter turn: a radius
// too large for the gap makes Dubins loop around instead.
bool plain_path(const ArclinePath& path, double turn_rad) {
  const double turning = (path.segment_length_m[0] + path.segment_length_m[2]) / path.radius_m;
  return turning <= std::fabs(turn_rad) + kPi / 2.0;
}

}  // namespace

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
    const std::vector<int>& ins = in_by_node[static_cast<int>(ni)];
    const std::vector<int>& outs = out_by_node[static_cast<int>(ni)];
    if (node.kind == NodeKind::kTransition) {
      connect_transition(ins, outs);
      continue;
    }
    node.segment_token = map_.road_segment(node.area, true);
    connect_junction(ins, outs);
    make_crossings(static_cast<int>(ni));
  }
}

// Straight on by lane index (the outer lanes of a wider road fork off), the near turn from
// and to the curb-side lanes, the far turn from and to the innermost ones; a turn pocket
// takes the far turn only and the lanes beside it none.
void WorldBuilder::connect_junction(const std::vector<int>& ins, const std::vector<int>& outs) {
  for (int a : ins) {
    const Pose2 A = lane_end_pose(world_.lanes[static_cast<size_t>(a)]);
    const LaneBuild& la = builds_[static_cast<size_t>(a)];
    const int a_index = la.index - (la.group_pocket && !la.pocket ? 1 : 0);
    const int a_group = la.group_size - (la.group_pocket ? 1 : 0);
    std::vector<int> moves;  // out lanes
    std::vector<int> fallback;
    for (int b : outs) {
      const LaneBuild& lb = builds_[static_cast<size_t>(b)];
      if (lb.piece == la.piece) continue;  // no U-turns
      const Pose2& B = world_.lanes[static_cast<size_t>(b)].paths.front().start_pose;
      const double turn = geometry::wrap_angle_devkit(B.yaw - A.yaw);
      if (std::fabs(turn) > kMaxTurnRad) continue;
      const bool straight = std::fabs(turn) < kPi / 4.0;
      const bool near_turn = !straight && ((turn < 0) == rht_);
      const bool far_turn = !straight && !near_turn;
      bool take = false;
      if (la.pocket) take = far_turn && lb.index == 0;
      else if (straight) take = lb.index == std::min(a_index, lb.group_size - 1);
      else if (near_turn) take = a_index == a_group - 1 && lb.index == lb.group_size - 1;
      else take = !la.group_pocket && a_index == 0 && lb.index == 0;
      if (take) moves.push_back(b);
      else if (lb.index == (near_turn ? lb.group_size - 1 : 0) && (!la.pocket || far_turn)) fallback.push_back(b);
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
      if (la.piece == lb.piece || la.pocket) continue;
      const double turn =
          std::fabs(geometry::wrap_angle_devkit(B.yaw - lane_end_pose(world_.lanes[static_cast<size_t>(a)]).yaw));
      if (turn > kMaxTurnRad) continue;
      const double cost = (turn < kPi / 4.0 ? 0.0 : 100.0) + std::abs(la.index - lb.index);
      if (cost < best_cost) best_cost = cost, best = a;
    }
    if (best >= 0) add_connector(best, b);
  }
}

// Each incoming lane continues into the nearest outgoing lane heading its way (pockets
// excepted); outgoing lanes nobody reaches — added lanes, a pocket opening, a ramp —
// fork off the nearest incoming lane, and a lane that ends merges into its neighbour.
void WorldBuilder::connect_transition(const std::vector<int>& ins, const std::vector<int>& outs) {
  auto heading_along = [](const Pose2& p, const Pose2& q) {
    return std::fabs(geometry::wrap_angle_devkit(q.yaw - p.yaw)) < kMaxTransitionTurnRad;
  };
  for (int a : ins) {
    const Pose2 A = lane_end_pose(world_.lanes[static_cast<size_t>(a)]);
    int best = -1;
    double best_m = 1e300;
    for (int b : outs) {
      const LaneBuild& lb = builds_[static_cast<size_t>(b)];
      const Pose2& B = world_.lanes[static_cast<size_t>(b)].paths.front().start_pose;
      if (lb.piece == builds_[static_cast<size_t>(a)].piece || lb.pocket || !heading_along(A, B)) continue;
      const double d = std::fabs(lateral_m(A, B));
      if (d < best_m) best_m = d, best = b;
    }
    if (best >= 0) add_connector(a, best);
  }
  for (int b : outs) {
    if (!world_.lanes[static_cast<size_t>(b)].incoming.empty()) continue;
    const Pose2& B = world_.lanes[static_cast<size_t>(b)].paths.front().start_pose;
    int best = -1;
    double best_m = 1e300;
    for (int a : ins) {
      const Pose2 A = lane_end_pose(world_.lanes[static_cast<size_t>(a)]);
      if (builds_[static_cast<size_t>(a)].piece == builds_[static_cast<size_t>(b)].piece || !heading_along(A, B))
        continue;
      const double d = std::fabs(lateral_m(B, A));
      if (d < best_m) best_m = d, best = a;
    }
    if (best >= 0) add_connector(best, b);
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
  // Lane ends that are not aligned (a lane shifting sideways, a skewed arm): the largest
  // radius that does not loop.
  for (double r = 400.0; !plain_path(path, turn) && r >= 1.0; r *= 0.85) path = dubins_path(A, B, r);
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

}  // namespace nsg::synth::world_detail

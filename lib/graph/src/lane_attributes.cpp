#include "nsg/graph/lane_attributes.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>
#include <utility>
#include <vector>

#include "nsg/graph/segment_index.h"

namespace nsg::graph {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr const char* kTurnNames[] = {"straight", "left", "right", "u_turn"};
constexpr const char* kJunctionNames[] = {"none", "split", "merge", "both"};

double heading_rad(const Node& a, const Node& b) { return std::atan2(b.y_m - a.y_m, b.x_m - a.x_m); }

// a − b wrapped into (−π, π].
double angle_between(double a, double b) {
  double d = std::fmod(a - b, 2.0 * kPi);
  if (d <= -kPi) d += 2.0 * kPi;
  if (d > kPi) d -= 2.0 * kPi;
  return d;
}

Turn turn_of(const LaneGraph& graph, const Lane& lane) {
  if (lane.nodes.size() < 2) return Turn::kStraight;
  const auto node = [&](size_t k) -> const Node& { return graph.nodes[lane.nodes[k]]; };
  const size_t n = lane.nodes.size();
  const double change_deg =
      angle_between(heading_rad(node(n - 2), node(n - 1)), heading_rad(node(0), node(1))) * 180.0 / kPi;
  if (std::abs(change_deg) <= kStraightMaxDeg) return Turn::kStraight;
  if (std::abs(change_deg) >= kUTurnMinDeg) return Turn::kUTurn;
  return change_deg > 0.0 ? Turn::kLeft : Turn::kRight;
}

void set_junctions(LaneGraph& graph) {
  std::vector<int32_t> in(graph.nodes.size(), 0), out(graph.nodes.size(), 0);
  for (const Edge& e : graph.edges) {
    ++out[static_cast<size_t>(e.source)];
    ++in[static_cast<size_t>(e.target)];
  }
  for (size_t k = 0; k < graph.nodes.size(); ++k) {
    const bool split = out[k] >= 2, merge = in[k] >= 2;
    graph.nodes[k].junction = split && merge ? Junction::kBoth
                              : split        ? Junction::kSplit
                              : merge        ? Junction::kMerge
                                             : Junction::kNone;
  }
}

// Heading of lane `lane` at its k-th node: along the chord of its neighbours (one-sided at
// the ends).
double heading_at(const LaneGraph& graph, const Lane& lane, size_t k) {
  const size_t a = k == 0 ? 0 : k - 1;
  const size_t b = std::min(k + 1, lane.nodes.size() - 1);
  return heading_rad(graph.nodes[lane.nodes[a]], graph.nodes[lane.nodes[b]]);
}

// The lane changes from one node of lane `from`: per other lane near it, the nearest point
// of that lane's centreline, and an edge to the nearer end of its segment if that point
// passes the rule.
void lane_changes_from(const LaneGraph& graph, const SegmentIndex& index, int32_t from, size_t k,
                       std::vector<LaneChange>& out) {
  const Lane& lane = graph.lanes[static_cast<size_t>(from)];
  const int32_t node = lane.nodes[k];
  const Node& p = graph.nodes[static_cast<size_t>(node)];
  struct Nearest {
    double distance_m;
    int32_t edge;
    double t;
  };
  std::map<int32_t, Nearest> nearest;  // other lane → its nearest point (ties: the first edge)
  const double r = kLaneChangeMaxOffsetM;
  for (int32_t e : index.query_box(p.x_m - r, p.y_m - r, p.x_m + r, p.y_m + r)) {
    const Edge& edge = graph.edges[static_cast<size_t>(e)];
    if (edge.lane == from || graph.lanes[static_cast<size_t>(edge.lane)].is_connector) continue;
    const Node& a = graph.nodes[static_cast<size_t>(edge.source)];
    const Node& b = graph.nodes[static_cast<size_t>(edge.target)];
    const NearestEdge near = closest_on_segment(a.x_m, a.y_m, b.x_m, b.y_m, p.x_m, p.y_m);
    auto [it, fresh] = nearest.emplace(edge.lane, Nearest{near.distance_m, e, near.t});
    if (!fresh && near.distance_m < it->second.distance_m) it->second = {near.distance_m, e, near.t};
  }
  const double heading = heading_at(graph, lane, k);
  const double max_turn_rad = kLaneChangeMaxHeadingDeg * kPi / 180.0;
  for (const auto& [to, found] : nearest) {
    if (found.distance_m < kLaneChangeMinOffsetM || found.distance_m > kLaneChangeMaxOffsetM) continue;
    const Edge& edge = graph.edges[static_cast<size_t>(found.edge)];
    const Lane& other = graph.lanes[static_cast<size_t>(to)];
    if ((found.t == 0.0 && edge.source == other.nodes.front()) || (found.t == 1.0 && edge.target == other.nodes.back()))
      continue;  // beside the other lane's start or end, not beside the lane
    const double other_heading =
        heading_rad(graph.nodes[static_cast<size_t>(edge.source)], graph.nodes[static_cast<size_t>(edge.target)]);
    if (std::abs(angle_between(other_heading, heading)) > max_turn_rad) continue;
    out.push_back({node, found.t < 0.5 ? edge.source : edge.target, from, to});
  }
}

void set_lane_changes(LaneGraph& graph) {
  graph.lane_changes.clear();
  if (graph.edges.empty()) return;
  const SegmentIndex index(graph);
  for (size_t l = 0; l < graph.lanes.size(); ++l) {
    const Lane& lane = graph.lanes[l];
    if (lane.is_connector) continue;
    for (size_t k = 0; k < lane.nodes.size(); ++k)
      lane_changes_from(graph, index, static_cast<int32_t>(l), k, graph.lane_changes);
  }
  auto& changes = graph.lane_changes;
  std::sort(changes.begin(), changes.end(), [](const LaneChange& x, const LaneChange& y) {
    return std::tie(x.source, x.target, x.source_lane, x.target_lane) <
           std::tie(y.source, y.target, y.source_lane, y.target_lane);
  });
  // A node shared by two lanes (a joint) is visited from both: one edge per node pair.
  changes.erase(std::unique(changes.begin(), changes.end(),
                            [](const LaneChange& x, const LaneChange& y) {
                              return x.source == y.source && x.target == y.target;
                            }),
                changes.end());
}

// Even-odd rule over a ring of map nodes (not closed); false for a ring with an unresolved node.
bool inside_ring(const nuscenes::MapExpansion& map, const std::vector<nuscenes::MapIndex>& ring, double x, double y) {
  bool inside = false;
  for (size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++) {
    if (ring[i] == nuscenes::kNoMapIndex || ring[j] == nuscenes::kNoMapIndex) return false;
    const nuscenes::MapNode& a = map.nodes()[ring[i]];
    const nuscenes::MapNode& b = map.nodes()[ring[j]];
    if ((a.y_m > y) != (b.y_m > y) && x < (b.x_m - a.x_m) * (y - a.y_m) / (b.y_m - a.y_m) + a.x_m) inside = !inside;
  }
  return inside;
}

bool inside_polygon(const nuscenes::MapExpansion& map, const nuscenes::MapPolygon& polygon, double x, double y) {
  if (polygon.exterior_nodes.size() < 3 || !inside_ring(map, polygon.exterior_nodes, x, y)) return false;
  for (const nuscenes::MapHole& hole : polygon.holes)
    if (hole.nodes.size() >= 3 && inside_ring(map, hole.nodes, x, y)) return false;
  return true;
}

}  // namespace

void add_lane_attributes(LaneGraph& graph) {
  for (Lane& lane : graph.lanes) lane.turn = turn_of(graph, lane);
  set_junctions(graph);
  set_lane_changes(graph);
}

void mark_intersections(LaneGraph& graph, const nuscenes::MapExpansion& map) {
  // Each intersection polygon with its exterior's bounding box, so a lane's middle is
  // tested against the few polygons around it (a city map has hundreds of them).
  struct Area {
    const nuscenes::MapPolygon* polygon;
    double x0, y0, x1, y1;
  };
  std::vector<Area> areas;
  for (const nuscenes::RoadSegment& segment : map.road_segments()) {
    if (!segment.is_intersection || segment.polygon == nuscenes::kNoMapIndex ||
        segment.polygon >= map.polygons().size())
      continue;
    Area a{&map.polygons()[segment.polygon], 1e300, 1e300, -1e300, -1e300};
    for (nuscenes::MapIndex n : a.polygon->exterior_nodes) {
      if (n == nuscenes::kNoMapIndex || n >= map.nodes().size()) continue;
      const nuscenes::MapNode& p = map.nodes()[n];
      a.x0 = std::min(a.x0, p.x_m), a.y0 = std::min(a.y0, p.y_m);
      a.x1 = std::max(a.x1, p.x_m), a.y1 = std::max(a.y1, p.y_m);
    }
    areas.push_back(a);
  }
  for (Lane& lane : graph.lanes) {
    lane.in_intersection = false;
    if (lane.nodes.empty()) continue;
    const Node& middle = graph.nodes[static_cast<size_t>(lane.nodes[lane.nodes.size() / 2])];
    for (const Area& a : areas) {
      if (middle.x_m < a.x0 || middle.x_m > a.x1 || middle.y_m < a.y0 || middle.y_m > a.y1) continue;
      if (inside_polygon(map, *a.polygon, middle.x_m, middle.y_m)) {
        lane.in_intersection = true;
        break;
      }
    }
  }
}

const char* turn_name(Turn turn) { return kTurnNames[static_cast<int>(turn)]; }
const char* junction_name(Junction junction) { return kJunctionNames[static_cast<int>(junction)]; }

bool turn_from_name(const std::string& name, Turn* turn) {
  for (int k = 0; k < 4; ++k)
    if (name == kTurnNames[k]) {
      *turn = static_cast<Turn>(k);
      return true;
    }
  return false;
}

bool junction_from_name(const std::string& name, Junction* junction) {
  for (int k = 0; k < 4; ++k)
    if (name == kJunctionNames[k]) {
      *junction = static_cast<Junction>(k);
      return true;
    }
  return false;
}

}  // namespace nsg::graph

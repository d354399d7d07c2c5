#include "nsg/graph/clip.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <unordered_map>

namespace nsg::graph {

double TileGraph::total_length_m() const {
  double total = 0.0;
  for (const TileEdge& e : edges)
    total += std::hypot(nodes[e.target].x_m - nodes[e.source].x_m, nodes[e.target].y_m - nodes[e.source].y_m);
  return total;
}

bool clip_segment(double ax, double ay, double bx, double by, const TileBounds& box, double* t0, double* t1) {
  const double dx = bx - ax, dy = by - ay;
  double lo = 0.0, hi = 1.0;
  // Each border as p·t ≤ q.
  const double p[4] = {-dx, dx, -dy, dy};
  const double q[4] = {ax - box.x_west_m, box.x_east_m - ax, ay - box.y_south_m, box.y_north_m - ay};
  for (int i = 0; i < 4; ++i) {
    if (p[i] == 0.0) {
      if (q[i] < 0.0) return false;  // parallel and outside
      continue;
    }
    const double r = q[i] / p[i];
    if (p[i] < 0.0) {
      if (r > lo) lo = r;
    } else if (r < hi) {
      hi = r;
    }
    if (lo > hi) return false;
  }
  if (lo >= hi && !(dx == 0.0 && dy == 0.0)) return false;  // touches a single point
  *t0 = lo;
  *t1 = hi;
  return true;
}

namespace {

constexpr double kMinClippedPieceM = 1e-9;

class TileBuilder {
 public:
  TileBuilder(const TileBounds& bounds, double resolution_m) : bounds_(bounds), res_(resolution_m) {}

  int32_t graph_node(int32_t node, const Node& at) {
    auto [it, fresh] = from_graph_.emplace(node, 0);
    if (fresh) {
      it->second = add(at.x_m, at.y_m);
      tile_.nodes.back().junction = at.junction;
    }
    return it->second;
  }
  // The tile's node of a lane graph node, or −1 when no clipped edge uses it.
  int32_t node_of(int32_t node) const {
    const auto it = from_graph_.find(node);
    return it == from_graph_.end() ? -1 : it->second;
  }
  // The lane graph's nodes in the tile, ascending (a deterministic order).
  std::vector<int32_t> graph_nodes() const {
    std::vector<int32_t> out;
    out.reserve(from_graph_.size());
    for (const auto& entry : from_graph_) out.push_back(entry.first);
    std::sort(out.begin(), out.end());
    return out;
  }
  int32_t border_node(double x, double y) {
    auto [it, fresh] = border_.emplace(std::make_pair(x, y), 0);
    if (fresh) it->second = add(x, y);
    return it->second;
  }
  TileGraph take() { return std::move(tile_); }
  TileGraph& tile() { return tile_; }

 private:
  int32_t add(double x, double y) {
    TileNode n;
    n.id = static_cast<int32_t>(tile_.nodes.size());
    n.x_m = x;
    n.y_m = y;
    n.u_px = (x - bounds_.x_west_m) / res_ - 0.5;
    n.v_px = (bounds_.y_north_m - y) / res_ - 0.5;
    tile_.nodes.push_back(n);
    return n.id;
  }

  TileBounds bounds_;
  double res_;
  TileGraph tile_;
  std::unordered_map<int32_t, int32_t> from_graph_;
  std::map<std::pair<double, double>, int32_t> border_;
};

// The lane changes whose two nodes are in the tile: graph.lane_changes is sorted by source
// node, so each node's run is found by binary search.
void add_lane_changes(const LaneGraph& graph, TileBuilder& builder) {
  const auto by_source = [](const LaneChange& c, int32_t node) { return c.source < node; };
  std::vector<TileLaneChange>& out = builder.tile().lane_changes;
  for (int32_t node : builder.graph_nodes()) {
    auto it = std::lower_bound(graph.lane_changes.begin(), graph.lane_changes.end(), node, by_source);
    for (; it != graph.lane_changes.end() && it->source == node; ++it) {
      const int32_t target = builder.node_of(it->target);
      if (target < 0) continue;
      out.push_back(
          {builder.node_of(node), target, graph.lanes[it->source_lane].token, graph.lanes[it->target_lane].token});
    }
  }
  std::sort(out.begin(), out.end(), [](const TileLaneChange& a, const TileLaneChange& b) {
    return a.source != b.source ? a.source < b.source : a.target < b.target;
  });
}

}  // namespace

TileGraph clip_to_tile(const LaneGraph& graph, const SegmentIndex& index, const TileBounds& bounds,
                       double resolution_m) {
  TileBuilder builder(bounds, resolution_m);
  for (int32_t e : index.query_box(bounds.x_west_m, bounds.y_south_m, bounds.x_east_m, bounds.y_north_m)) {
    const Edge& edge = graph.edges[e];
    const Node& a = graph.nodes[edge.source];
    const Node& b = graph.nodes[edge.target];
    double t0 = 0.0, t1 = 1.0;
    if (!clip_segment(a.x_m, a.y_m, b.x_m, b.y_m, bounds, &t0, &t1)) continue;
    // An edge ending exactly on a border from outside can leave a rounding sliver (~1e-14 m)
    // inside; two such slivers into one lane start became one edge twice. Not a piece of lane.
    if ((t1 - t0) * graph.edge_length_m(edge) < kMinClippedPieceM) continue;
    const int32_t s = t0 == 0.0 ? builder.graph_node(edge.source, a)
                                : builder.border_node(a.x_m + t0 * (b.x_m - a.x_m), a.y_m + t0 * (b.y_m - a.y_m));
    const int32_t t = t1 == 1.0 ? builder.graph_node(edge.target, b)
                                : builder.border_node(a.x_m + t1 * (b.x_m - a.x_m), a.y_m + t1 * (b.y_m - a.y_m));
    if (s == t) continue;
    const Lane& lane = graph.lanes[edge.lane];
    builder.tile().edges.push_back({s, t, lane.token, lane.is_connector, lane.in_intersection, lane.turn});
  }
  add_lane_changes(graph, builder);
  return builder.take();
}

}  // namespace nsg::graph

#include "nsg/graph/tile_lanes.h"

#include <algorithm>
#include <map>
#include <unordered_map>

#include "nsg/core/error.h"

namespace nsg::graph {
namespace {

// Chains of one lane's edges (indices into tile.edges), each from its start to its end:
// starts are edges whose source no other edge of the lane enters; what is left is a loop,
// entered at its lowest edge index.
std::vector<std::vector<int32_t>> chains_of_lane(const TileGraph& tile, const std::vector<int32_t>& edges) {
  std::unordered_map<int32_t, int32_t> out_of;  // node → the lane's edge leaving it
  std::unordered_map<int32_t, int> entered;
  for (int32_t e : edges) {
    out_of.emplace(tile.edges[e].source, e);  // a second edge out of a node starts its own chain
    ++entered[tile.edges[e].target];
  }
  std::vector<bool> used(tile.edges.size(), false);
  std::vector<std::vector<int32_t>> chains;
  const auto follow = [&](int32_t e) {
    std::vector<int32_t> chain;
    while (!used[e]) {
      used[e] = true;
      chain.push_back(e);
      const auto next = out_of.find(tile.edges[e].target);
      if (next == out_of.end()) break;
      e = next->second;
    }
    chains.push_back(std::move(chain));
  };
  for (int32_t e : edges)
    if (!used[e] && (entered.count(tile.edges[e].source) == 0 || out_of.at(tile.edges[e].source) != e)) follow(e);
  for (int32_t e : edges)
    if (!used[e]) follow(e);
  return chains;
}

}  // namespace

LaneGraph lane_graph_from_tile(const TileGraph& tile, TileFrame frame, std::vector<int32_t>* tile_edge_of) {
  LaneGraph g;
  if (tile_edge_of != nullptr) tile_edge_of->clear();
  for (const TileNode& n : tile.nodes)
    g.nodes.push_back(frame == TileFrame::kPixels ? Node{n.u_px, n.v_px} : Node{n.x_m, n.y_m});
  const auto n_nodes = static_cast<int32_t>(tile.nodes.size());
  std::vector<std::string> order;  // tokens by first appearance
  std::map<std::string, std::vector<int32_t>> edges_of;
  for (size_t k = 0; k < tile.edges.size(); ++k) {
    const TileEdge& e = tile.edges[k];
    NSG_CHECK(e.source >= 0 && e.source < n_nodes && e.target >= 0 && e.target < n_nodes, DataError, "tile graph",
              "edge " + std::to_string(k), "node indices in [0, " + std::to_string(n_nodes) + ")");
    auto& list = edges_of[e.lane_token];
    if (list.empty()) order.push_back(e.lane_token);
    list.push_back(static_cast<int32_t>(k));
  }
  std::vector<std::vector<int32_t>> chains;
  std::vector<std::string> tokens;
  for (const std::string& token : order)
    for (auto& chain : chains_of_lane(tile, edges_of[token])) {
      chains.push_back(std::move(chain));
      tokens.push_back(token);
    }
  std::vector<size_t> by_first(chains.size());
  for (size_t c = 0; c < chains.size(); ++c) by_first[c] = c;
  std::stable_sort(by_first.begin(), by_first.end(), [&](size_t a, size_t b) { return chains[a][0] < chains[b][0]; });

  std::multimap<int32_t, int32_t> lanes_starting_at;
  for (size_t c : by_first) {
    const auto lane = static_cast<int32_t>(g.lanes.size());
    Lane l;
    l.token = tokens[c];
    l.nodes.push_back(tile.edges[chains[c][0]].source);
    for (int32_t e : chains[c]) {
      g.edges.push_back({tile.edges[e].source, tile.edges[e].target, lane});
      if (tile_edge_of != nullptr) tile_edge_of->push_back(e);
      l.nodes.push_back(tile.edges[e].target);
      l.length_m += g.edge_length_m(g.edges.back());
    }
    lanes_starting_at.emplace(l.nodes.front(), lane);
    g.lanes.push_back(std::move(l));
  }
  for (size_t a = 0; a < g.lanes.size(); ++a) {
    auto [lo, hi] = lanes_starting_at.equal_range(g.lanes[a].nodes.back());
    for (auto it = lo; it != hi; ++it)
      if (it->second != static_cast<int32_t>(a)) g.lanes[a].successors.push_back(it->second);
    std::sort(g.lanes[a].successors.begin(), g.lanes[a].successors.end());
  }
  // Lane changes keep their nodes (the tile's); their lanes are not needed by the readers of
  // a tile's lane graph (the adaptive ground truth links nodes), so they stay −1.
  for (const TileLaneChange& c : tile.lane_changes) {
    NSG_CHECK(c.source >= 0 && c.source < n_nodes && c.target >= 0 && c.target < n_nodes, DataError, "tile graph",
              "lane change " + std::to_string(c.source) + " -> " + std::to_string(c.target),
              "node indices in [0, " + std::to_string(n_nodes) + ")");
    g.lane_changes.push_back({c.source, c.target, -1, -1});
  }
  return g;
}

}  // namespace nsg::graph

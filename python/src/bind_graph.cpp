// The paper's adaptive ground truth on one tile: graph::lane_graph_from_tile +
// graph::project_onto_lanes (nsgraph.adaptive_ground_truth).
#include "bindings.h"
#include "convert.h"
#include "nsg/core/error.h"
#include "nsg/graph/projection.h"
#include "nsg/graph/tile_lanes.h"

namespace nsg::py_bind {
namespace {

// Coordinates are in one frame (metres or pixels, the caller's choice): the tile graph is
// built with x = u = the given coordinate so lane_graph_from_tile reads either.
graph::TileGraph tile_graph_arg(const Points& nodes, const Pairs& edges, const std::vector<std::string>& tokens,
                                const Pairs& lane_changes) {
  graph::TileGraph g;
  const auto xy = points_arg(nodes, "graph nodes");
  for (size_t k = 0; k < xy.size(); ++k)
    g.nodes.push_back({static_cast<int32_t>(k), xy[k][0], xy[k][1], xy[k][0], xy[k][1]});
  const auto ij = pairs_arg(edges, "graph edges");
  NSG_CHECK(tokens.size() == ij.size(), ConfigError, "", "graph lane_tokens",
            "one lane token per edge (" + std::to_string(ij.size()) + "), got " + std::to_string(tokens.size()));
  for (size_t k = 0; k < ij.size(); ++k) {
    for (int64_t i : ij[k])
      NSG_CHECK(i >= 0 && i < static_cast<int64_t>(xy.size()), DataError, "", "graph edges[" + std::to_string(k) + "]",
                "node indices in [0, " + std::to_string(xy.size()) + ")");
    g.edges.push_back({static_cast<int32_t>(ij[k][0]), static_cast<int32_t>(ij[k][1]), tokens[k]});
  }
  const auto changes = pairs_arg(lane_changes, "graph lane_changes");
  for (size_t k = 0; k < changes.size(); ++k) {
    for (int64_t i : changes[k])
      NSG_CHECK(i >= 0 && i < static_cast<int64_t>(xy.size()), DataError, "",
                "graph lane_changes[" + std::to_string(k) + "]",
                "node indices in [0, " + std::to_string(xy.size()) + ")");
    g.lane_changes.push_back({static_cast<int32_t>(changes[k][0]), static_cast<int32_t>(changes[k][1]), "", ""});
  }
  return g;
}

py::dict adaptive_ground_truth(const Points& nodes, const Pairs& edges, const std::vector<std::string>& tokens,
                               const Pairs& lane_changes, const Points& proposals, double max_distance,
                               double max_follow) {
  const graph::TileGraph tile = tile_graph_arg(nodes, edges, tokens, lane_changes);
  std::vector<graph::Node> points;
  for (const auto& p : points_arg(proposals, "proposals")) points.push_back({p[0], p[1]});
  graph::ProjectionOptions options;
  options.max_distance_m = max_distance;
  options.max_follow_m = max_follow;
  std::vector<int32_t> tile_edge_of;
  graph::LaneGraph lanes;
  graph::AdaptiveGroundTruth gt;
  {
    py::gil_scoped_release release;
    lanes = graph::lane_graph_from_tile(tile, graph::TileFrame::kMetres, &tile_edge_of);
    const graph::SegmentIndex index(lanes);
    gt = graph::project_onto_lanes(lanes, index, points, options);
  }
  std::vector<std::array<double, 2>> xy;
  std::vector<int64_t> input, edge, piece;
  std::vector<double> along, distance;
  py::list lane_tokens;
  for (const graph::ProjectedPoint& p : gt.points) {
    xy.push_back({p.x_m, p.y_m});
    input.push_back(p.input);
    edge.push_back(tile_edge_of[static_cast<size_t>(p.edge)]);
    piece.push_back(p.lane);
    along.push_back(p.along_lane_m);
    distance.push_back(p.distance_m);
    lane_tokens.append(py::str(lanes.lanes[static_cast<size_t>(p.lane)].token));
  }
  std::vector<std::array<int64_t, 2>> connections;
  for (const auto& [a, b] : gt.connections) connections.push_back({a, b});
  py::dict d;
  d["points"] = pairs_to_numpy(xy);
  d["input"] = ints_to_numpy(input);
  d["edge"] = ints_to_numpy(edge);
  d["lane"] = ints_to_numpy(piece);
  d["lane_tokens"] = lane_tokens;
  d["along"] = doubles_to_numpy(along);
  d["distance"] = doubles_to_numpy(distance);
  d["edges"] = pairs_to_numpy(connections);
  std::vector<std::array<int64_t, 2>> lateral;
  for (const auto& [a, b] : gt.lane_changes) lateral.push_back({a, b});
  d["lane_changes"] = pairs_to_numpy(lateral);
  return d;
}

}  // namespace

void bind_graph(py::module_& m) {
  m.def("adaptive_ground_truth", &adaptive_ground_truth, py::arg("nodes"), py::arg("edges"), py::arg("lane_tokens"),
        py::arg("lane_changes"), py::arg("proposals"), py::arg("max_distance"), py::arg("max_follow"));
}

}  // namespace nsg::py_bind

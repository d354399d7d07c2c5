// The paper's adaptive ground truth on one tile: graph::lane_graph_from_tile +
// graph::project_onto_lanes (nsgraph.adaptive_ground_truth); a map's lane graph
// (skeleton::graphify, nsgraph.graphify).
#include <cstring>
#include <optional>

#include "bindings.h"
#include "convert.h"
#include "nsg/core/error.h"
#include "nsg/graph/projection.h"
#include "nsg/graph/tile_lanes.h"
#include "nsg/skeleton/graphify.h"

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

// Keyword arguments through graphify's declarations (unknown keys and ranges refused by
// name, as `--set` refuses them).
skeleton::GraphifyOptions graphify_options(const py::dict& kwargs) {
  skeleton::GraphifyOptions options;
  for (const auto& [k, v] : kwargs) {
    const std::string key = py::str(k);
    nlohmann::json value;
    if (py::isinstance<py::bool_>(v)) value = v.cast<bool>();
    else if (py::isinstance<py::int_>(v)) value = v.cast<int64_t>();
    else if (py::isinstance<py::float_>(v)) value = v.cast<double>();
    else value = std::string(py::str(v));
    skeleton::graphify_option_table().set(options, key, value, "nsgraph.graphify");
  }
  return options;
}

py::dict graph_dict(const metrics::Graph& g) {
  std::vector<std::array<double, 2>> nodes;
  for (const auto& n : g.nodes) nodes.push_back({n.u, n.v});
  py::dict d;
  d["nodes"] = pairs_to_numpy(nodes);
  d["edges"] = pairs_to_numpy(g.edges);
  d["node_scores"] = py::array_t<double>(static_cast<py::ssize_t>(g.node_scores.size()), g.node_scores.data());
  d["edge_scores"] = py::array_t<double>(static_cast<py::ssize_t>(g.edge_scores.size()), g.edge_scores.data());
  return d;
}

// A 2-D uint8, uint16 or float32 array as a cv::Mat (copied: the library owns its map).
cv::Mat map_arg(const py::array& a) {
  NSG_CHECK(a.ndim() == 2, DataError, "", "map", "a 2-D array, got " + std::to_string(a.ndim()) + " dimension(s)");
  const py::dtype dt = a.dtype();
  // By kind and size (native byte order: the Python side converts others).
  const int type = dt.kind() == 'u' && dt.itemsize() == 1   ? CV_8U
                   : dt.kind() == 'u' && dt.itemsize() == 2 ? CV_16U
                   : dt.kind() == 'f' && dt.itemsize() == 4 ? CV_32F
                                                            : -1;
  NSG_CHECK(type >= 0, DataError, "", "map",
            "dtype uint8, uint16 or float32, got " + dt.attr("name").cast<std::string>());
  const auto rows = a.shape(0), cols = a.shape(1);
  const bool ok = rows >= 1 && cols >= 1 && rows <= skeleton::kMaxMapSidePx && cols <= skeleton::kMaxMapSidePx;
  NSG_CHECK(ok, DataError, "", "map",
            "each side 1 … " + std::to_string(skeleton::kMaxMapSidePx) + " px, got " + std::to_string(rows) + " x " +
                std::to_string(cols));
  const py::array c = py::array::ensure(a, py::array::c_style);
  cv::Mat m(static_cast<int>(rows), static_cast<int>(cols), type);
  std::memcpy(m.data, c.data(), m.total() * m.elemSize());
  return m;
}

// graphify's directed mode: None (undirected), a heading file's path or a 2-D array.
std::optional<cv::Mat> heading_arg(const py::object& heading, std::string& name) {
  if (heading.is_none()) return std::nullopt;
  if (py::isinstance<py::str>(heading)) {
    name = heading.cast<std::string>();
    return skeleton::read_map_file(name);
  }
  name = "heading";
  return map_arg(heading.cast<py::array>());
}

py::dict graphify_one(const cv::Mat& map, const std::string& map_name, const py::object& heading,
                      const py::dict& kwargs) {
  const skeleton::GraphifyOptions options = graphify_options(kwargs);
  std::string heading_name;
  const std::optional<cv::Mat> h = heading_arg(heading, heading_name);
  metrics::Graph g;
  {
    py::gil_scoped_release release;
    g = skeleton::graphify(map, options, map_name, h ? &*h : nullptr, heading_name);
  }
  return graph_dict(g);
}

py::dict graphify_array(const py::array& map, const py::object& heading, const py::dict& kwargs) {
  return graphify_one(map_arg(map), "map", heading, kwargs);
}

py::dict graphify_file(const std::string& path, const py::object& heading, const py::dict& kwargs) {
  cv::Mat m;
  {
    py::gil_scoped_release release;
    m = skeleton::read_map_file(path);
  }
  return graphify_one(m, path, heading, kwargs);
}

}  // namespace

void bind_graph(py::module_& m) {
  m.def("graphify_array", &graphify_array, py::arg("map"), py::arg("heading"), py::arg("options"));
  m.def("graphify_file", &graphify_file, py::arg("path"), py::arg("heading"), py::arg("options"));
  m.def("adaptive_ground_truth", &adaptive_ground_truth, py::arg("nodes"), py::arg("edges"), py::arg("lane_tokens"),
        py::arg("lane_changes"), py::arg("proposals"), py::arg("max_distance"), py::arg("max_follow"));
}

}  // namespace nsg::py_bind

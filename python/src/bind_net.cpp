// LaneGraphNet's post-processing and the paper's direction rule for the PyTorch model
// (nsgraph.models): lib/model's net_graph.h and direction.h, so Python and the C++ ONNX
// predictor share one definition.
#include "bindings.h"
#include "convert.h"
#include "nsg/core/error.h"
#include "nsg/model/direction.h"
#include "nsg/model/net_graph.h"
#include "nsg/model/pairs.h"

namespace nsg::py_bind {
namespace {

using Floats = py::array_t<float, py::array::c_style | py::array::forcecast>;
using model::NetGraphOptions;

// A (C, h, w) float32 array as C matrices (copies); ConfigError naming `what` otherwise.
std::vector<cv::Mat> planes_arg(const Floats& a, const std::string& what, int channels = -1) {
  NSG_CHECK(a.ndim() == 3 && (channels < 0 || a.shape(0) == channels), ConfigError, "", what,
            "a (" + (channels < 0 ? std::string("C") : std::to_string(channels)) + ", h, w) float32 array");
  std::vector<cv::Mat> out;
  const int h = static_cast<int>(a.shape(1)), w = static_cast<int>(a.shape(2));
  for (py::ssize_t c = 0; c < a.shape(0); ++c)
    out.push_back(cv::Mat(h, w, CV_32F, const_cast<float*>(a.data(c, 0, 0))).clone());
  return out;
}

std::vector<std::array<int, 2>> int_pairs(const Pairs& a, const std::string& what) {
  std::vector<std::array<int, 2>> out;
  for (const auto& p : pairs_arg(a, what)) out.push_back({static_cast<int>(p[0]), static_cast<int>(p[1])});
  return out;
}

py::array_t<int64_t> pairs_out(const std::vector<std::array<int, 2>>& pairs) {
  std::vector<std::array<int64_t, 2>> rows;
  for (const auto& p : pairs) rows.push_back({p[0], p[1]});
  return pairs_to_numpy(rows);
}

py::dict options_dict() {
  const NetGraphOptions o;
  py::dict d;
  d["stride_px"] = o.stride_px;
  d["anchor_threshold"] = o.anchor_threshold;
  d["nms_radius_px"] = o.nms_radius_px;
  d["vote_radius_cells"] = o.vote_radius_cells;
  d["pair_radius_px"] = o.pair_radius_px;
  d["segment_samples"] = o.segment_samples;
  d["min_connection_score"] = o.min_connection_score;
  d["shortcut_radius_px"] = o.shortcut_radius_px;
  d["min_node_score"] = o.extraction.min_node_score;
  d["min_edge_score"] = o.extraction.min_edge_score;
  return d;
}

model::AnchorSet anchor_set(const Points& points, const std::vector<double>& scores, const Floats& votes) {
  model::AnchorSet a;
  a.points = points_arg(points, "points");
  a.scores = scores;
  NSG_CHECK(votes.ndim() == 2 && votes.shape(0) == static_cast<py::ssize_t>(a.points.size()) &&
                votes.shape(1) == model::kDirectionClasses,
            ConfigError, "", "votes", "a (K, 19) array, one row per point");
  NSG_CHECK(scores.size() == a.points.size(), ConfigError, "", "scores", "one per point");
  for (size_t k = 0; k < a.points.size(); ++k) {
    model::Votes v{};
    for (int c = 0; c < model::kDirectionClasses; ++c) v[static_cast<size_t>(c)] = votes.at(k, c);
    a.votes.push_back(v);
    a.mean_dir.push_back(model::mean_direction_px(v));
  }
  return a;
}

py::dict net_anchors(const Floats& heat, const Floats& offset, const Floats& direction, int tile_size_px) {
  NSG_CHECK(heat.ndim() == 2, ConfigError, "", "heat", "an (h, w) float32 array");
  model::NetMaps maps;
  maps.heat =
      cv::Mat(static_cast<int>(heat.shape(0)), static_cast<int>(heat.shape(1)), CV_32F, const_cast<float*>(heat.data()))
          .clone();
  const auto off = planes_arg(offset, "offset", 2);
  maps.offset_u = off[0];
  maps.offset_v = off[1];
  maps.direction = planes_arg(direction, "direction", model::kDirectionClasses);
  maps.tile_size_px = tile_size_px;
  const NetGraphOptions o;
  model::AnchorSet a;
  std::vector<std::array<int, 2>> pairs;
  {
    py::gil_scoped_release release;
    a = model::net_anchors(maps, o);
    pairs = model::candidate_pairs(a.points, o.pair_radius_px);
  }
  py::array_t<float> votes(
      {static_cast<py::ssize_t>(a.points.size()), static_cast<py::ssize_t>(model::kDirectionClasses)});
  for (size_t k = 0; k < a.points.size(); ++k)
    for (int c = 0; c < model::kDirectionClasses; ++c) votes.mutable_at(k, c) = a.votes[k][static_cast<size_t>(c)];
  py::dict d;
  d["points"] = pairs_to_numpy(a.points);
  d["scores"] = doubles_to_numpy(a.scores);
  d["votes"] = votes;
  d["pairs"] = pairs_out(pairs);
  return d;
}

py::array_t<float> net_pair_inputs(const Floats& features, const Points& points, const Pairs& pairs) {
  const auto planes = planes_arg(features, "features");
  const auto pts = points_arg(points, "points");
  const auto pr = int_pairs(pairs, "pairs");
  cv::Mat x;
  {
    py::gil_scoped_release release;
    x = model::net_pair_inputs(planes, pts, pr, NetGraphOptions{});
  }
  py::array_t<float> out({static_cast<py::ssize_t>(x.rows), static_cast<py::ssize_t>(x.cols)});
  for (int r = 0; r < x.rows; ++r)
    for (int c = 0; c < x.cols; ++c) out.mutable_at(r, c) = x.at<float>(r, c);
  return out;
}

py::dict net_graph(const Points& points, const std::vector<double>& scores, const Floats& votes, const Pairs& pairs,
                   const std::vector<double>& pair_scores, int tile_size_px) {
  const model::AnchorSet a = anchor_set(points, scores, votes);
  const auto pr = int_pairs(pairs, "pairs");
  metrics::Graph g;
  {
    py::gil_scoped_release release;
    g = model::net_graph(a, pr, pair_scores, tile_size_px, NetGraphOptions{});
  }
  std::vector<std::array<double, 2>> nodes;
  for (const auto& n : g.nodes) nodes.push_back({n.u, n.v});
  py::dict d;
  d["nodes"] = pairs_to_numpy(nodes);
  d["edges"] = pairs_to_numpy(g.edges);
  d["node_scores"] = doubles_to_numpy(g.node_scores);
  d["edge_scores"] = doubles_to_numpy(g.edge_scores);
  return d;
}

// LaneDirNet's class of each pixel-frame vector (du, dv): its 20° bin.
py::array_t<int64_t> direction_bins(const Points& vectors) {
  std::vector<int64_t> out;
  for (const auto& d : points_arg(vectors, "vectors"))
    out.push_back(model::direction_bin(model::map_angle(d[0], d[1])));
  return ints_to_numpy(out);
}

}  // namespace

void bind_net(py::module_& m) {
  m.def("net_graph_options", &options_dict);
  m.def("net_anchors", &net_anchors, py::arg("heat"), py::arg("offset"), py::arg("direction"), py::arg("tile_size_px"));
  m.def("net_pair_inputs", &net_pair_inputs, py::arg("features"), py::arg("points"), py::arg("pairs"));
  m.def("net_graph", &net_graph, py::arg("points"), py::arg("scores"), py::arg("votes"), py::arg("pairs"),
        py::arg("pair_scores"), py::arg("tile_size_px"));
  m.def("direction_bins", &direction_bins, py::arg("vectors"));
  m.def("orient_a_to_b", &model::orient_a_to_b, py::arg("a_uv"), py::arg("b_uv"), py::arg("mean_dir_a"),
        py::arg("mean_dir_b"));
  m.attr("DIRECTION_CLASSES") = model::kDirectionClasses;
}

}  // namespace nsg::py_bind

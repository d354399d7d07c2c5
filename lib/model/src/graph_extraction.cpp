// b1's graph from the skeleton's anchors (nsg::skeleton): orientation from LaneDirNet's
// votes, node and edge scores, and the paper's post-processing.
#include "nsg/model/graph_extraction.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "nsg/core/error.h"

namespace nsg::model {

metrics::Graph orient_and_score(const AnchorGraph& anchors, const cv::Mat& likelihood, const DirectionVotes& votes,
                                std::vector<double>* angle_deg) {
  metrics::Graph g;
  std::vector<std::array<double, 2>> mean_dir;
  const std::vector<Votes> anchor_votes = anchors.nodes.empty() ? std::vector<Votes>{} : votes(anchors.nodes);
  NSG_CHECK(anchor_votes.size() == anchors.nodes.size(), DataError, "", "direction votes", "one per anchor");
  for (size_t k = 0; k < anchors.nodes.size(); ++k) {
    const auto& p = anchors.nodes[k];
    g.nodes.push_back({p[0], p[1]});
    g.node_scores.push_back(sample_bilinear(likelihood, p[0], p[1]));
    mean_dir.push_back(mean_direction_px(anchor_votes[k]));
  }
  if (angle_deg) angle_deg->clear();
  for (const auto& pr : anchors.pairs) {
    const auto a = static_cast<size_t>(pr[0]), b = static_cast<size_t>(pr[1]);
    const bool forward = orient_a_to_b(anchors.nodes[a], anchors.nodes[b], mean_dir[a], mean_dir[b]);
    g.edges.push_back(forward ? std::array<int64_t, 2>{pr[0], pr[1]} : std::array<int64_t, 2>{pr[1], pr[0]});
    const double du = anchors.nodes[b][0] - anchors.nodes[a][0], dv = anchors.nodes[b][1] - anchors.nodes[a][1];
    if (angle_deg) {
      const double mu = mean_dir[a][0] + mean_dir[b][0], mv = mean_dir[a][1] + mean_dir[b][1];
      const double norm = std::hypot(du, dv) * std::hypot(mu, mv);
      // |cos| of the angle between the edge's axis and the predicted direction.
      const double c = norm > 0.0 ? std::fabs(du * mu + dv * mv) / norm : 0.0;
      angle_deg->push_back(std::acos(std::min(1.0, c)) * 180.0 / M_PI);
    }
    g.edge_scores.push_back(skeleton::segment_score(likelihood, anchors.nodes[a], anchors.nodes[b]));
  }
  return g;
}

void postprocess(metrics::Graph& graph, int tile_size_px, const ExtractionOptions& options,
                 const std::vector<double>* angle_deg) {
  const size_t n = graph.nodes.size();
  std::vector<char> node_ok(n, 1);
  for (size_t i = 0; i < n; ++i) node_ok[i] = graph.node_scores[i] >= options.min_node_score;
  const double max_len = options.max_edge_fraction * tile_size_px;
  std::vector<std::array<int64_t, 2>> edges;
  std::vector<double> edge_scores;
  std::vector<char> used(n, 0);
  for (size_t e = 0; e < graph.edges.size(); ++e) {
    const auto [i, j] = graph.edges[e];
    const auto& a = graph.nodes[static_cast<size_t>(i)];
    const auto& b = graph.nodes[static_cast<size_t>(j)];
    if (!node_ok[static_cast<size_t>(i)] || !node_ok[static_cast<size_t>(j)]) continue;
    if (graph.edge_scores[e] < options.min_edge_score) continue;
    if (std::hypot(b.u - a.u, b.v - a.v) > max_len) continue;
    if (angle_deg && options.max_direction_angle_deg < 90.0 && (*angle_deg)[e] > options.max_direction_angle_deg)
      continue;
    edges.push_back(graph.edges[e]);
    edge_scores.push_back(graph.edge_scores[e]);
    used[static_cast<size_t>(i)] = used[static_cast<size_t>(j)] = 1;
  }
  // Pieces (connected components) shorter than min_piece_length_px go.
  if (options.min_piece_length_px > 0.0) {
    std::vector<size_t> parent(n);
    std::iota(parent.begin(), parent.end(), size_t{0});
    auto find = [&](size_t x) {
      while (parent[x] != x) x = parent[x] = parent[parent[x]];
      return x;
    };
    for (const auto& e : edges) parent[find(static_cast<size_t>(e[0]))] = find(static_cast<size_t>(e[1]));
    std::vector<double> piece_length(n, 0.0);
    auto length = [&](const std::array<int64_t, 2>& e) {
      const auto& a = graph.nodes[static_cast<size_t>(e[0])];
      const auto& b = graph.nodes[static_cast<size_t>(e[1])];
      return std::hypot(b.u - a.u, b.v - a.v);
    };
    for (const auto& e : edges) piece_length[find(static_cast<size_t>(e[0]))] += length(e);
    std::vector<std::array<int64_t, 2>> kept;
    std::vector<double> kept_scores;
    std::fill(used.begin(), used.end(), 0);
    for (size_t e = 0; e < edges.size(); ++e) {
      if (piece_length[find(static_cast<size_t>(edges[e][0]))] < options.min_piece_length_px) continue;
      kept.push_back(edges[e]);
      kept_scores.push_back(edge_scores[e]);
      used[static_cast<size_t>(edges[e][0])] = used[static_cast<size_t>(edges[e][1])] = 1;
    }
    edges = std::move(kept);
    edge_scores = std::move(kept_scores);
  }
  // Isolated nodes go; the rest are renumbered in their original order.
  std::vector<int64_t> remap(n, -1);
  metrics::Graph out;
  for (size_t i = 0; i < n; ++i) {
    if (!used[i]) continue;
    remap[i] = static_cast<int64_t>(out.nodes.size());
    out.nodes.push_back(graph.nodes[i]);
    out.node_scores.push_back(graph.node_scores[i]);
  }
  for (auto& e : edges) e = {remap[static_cast<size_t>(e[0])], remap[static_cast<size_t>(e[1])]};
  out.edges = std::move(edges);
  out.edge_scores = std::move(edge_scores);
  graph = std::move(out);
}

metrics::Graph extract_graph(const cv::Mat& likelihood, const DirectionVotes& votes, const ExtractionOptions& options) {
  options.validate();
  NSG_CHECK(likelihood.type() == CV_32F && likelihood.rows == likelihood.cols, DataError, "", "likelihood",
            "a square CV_32F map");
  const AnchorGraph anchors = skeleton::skeleton_anchors(likelihood, options);
  std::vector<double> angle_deg;
  metrics::Graph g = orient_and_score(anchors, likelihood, votes, &angle_deg);
  postprocess(g, likelihood.rows, options, &angle_deg);
  return g;
}

}  // namespace nsg::model

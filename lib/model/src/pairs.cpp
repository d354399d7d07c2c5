#include "nsg/model/pairs.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "nsg/core/error.h"
#include "nsg/graph/projection.h"
#include "nsg/graph/segment_index.h"
#include "nsg/model/direction.h"
#include "nsg/model/graph_extraction.h"

namespace nsg::model {

std::vector<std::array<int, 2>> candidate_pairs(const std::vector<std::array<double, 2>>& anchors, double radius_px) {
  std::vector<std::array<int, 2>> pairs;
  const double r2 = radius_px * radius_px;
  for (size_t i = 0; i < anchors.size(); ++i) {
    for (size_t j = i + 1; j < anchors.size(); ++j) {
      const double du = anchors[j][0] - anchors[i][0], dv = anchors[j][1] - anchors[i][1];
      if (du * du + dv * dv <= r2) pairs.push_back({static_cast<int>(i), static_cast<int>(j)});
    }
  }
  return pairs;
}

std::vector<std::string> pair_feature_names() {
  return {"length_px",    "anchor_score_min",   "anchor_score_max",   "centre_along_min", "centre_along_mean",
          "centre_mid",   "anchor_along_min",   "anchor_along_mean",  "axis_cos_end_min", "axis_cos_end_max",
          "axis_cos_sum", "dir_agreement",      "dir_confidence_min", "background_max",   "rank_min",
          "rank_max",     "length_over_nn_min", "length_over_nn_max", "anchors_skipped"};
}

namespace {

double dist(const std::array<double, 2>& a, const std::array<double, 2>& b) {
  return std::hypot(b[0] - a[0], b[1] - a[1]);
}

// |cos| between the axis (du, dv) and a direction m; 0 without evidence.
double axis_cos(double du, double dv, const std::array<double, 2>& m) {
  const double n = std::hypot(du, dv) * std::hypot(m[0], m[1]);
  return n > 0.0 ? std::fabs(du * m[0] + dv * m[1]) / n : 0.0;
}

// How sure LaneDirNet is: |mean direction| over all votes (1 = every vote one bin), and the
// share of background votes.
std::pair<double, double> confidence_and_background(const Votes& v, const std::array<double, 2>& mean_dir) {
  double total = 0.0;
  for (float x : v) total += x;
  if (total <= 0.0) return {0.0, 1.0};
  return {std::hypot(mean_dir[0], mean_dir[1]) / total, v[kBackgroundClass] / total};
}

}  // namespace

cv::Mat pair_features(const AnchorSet& anchors, const std::vector<std::array<int, 2>>& pairs, const cv::Mat& likelihood,
                      const cv::Mat& anchor_score) {
  const auto& p = anchors.points;
  const size_t n = p.size();
  std::vector<double> nn(n, 0.0);
  for (size_t i = 0; i < n; ++i) {
    double best = 0.0;
    for (size_t k = 0; k < n; ++k) {
      if (k != i && (best == 0.0 || dist(p[i], p[k]) < best)) best = dist(p[i], p[k]);
    }
    nn[i] = best;
  }
  // Anchors strictly nearer to i than j is.
  auto rank = [&](size_t i, size_t j) {
    const double d = dist(p[i], p[j]);
    int r = 0;
    for (size_t k = 0; k < n; ++k) r += k != i && k != j && dist(p[i], p[k]) < d;
    return r;
  };
  constexpr int kAlong = 9;        // interior samples at t = 0.1 … 0.9
  constexpr double kSkipPx = 4.0;  // an anchor this close to the segment's interior is skipped
  cv::Mat out(static_cast<int>(pairs.size()), static_cast<int>(pair_feature_names().size()), CV_32F);
  for (size_t r = 0; r < pairs.size(); ++r) {
    const auto a = static_cast<size_t>(pairs[r][0]), b = static_cast<size_t>(pairs[r][1]);
    NSG_CHECK(a < n && b < n && a != b, DataError, "", "pair " + std::to_string(r), "two distinct anchor indices");
    const double du = p[b][0] - p[a][0], dv = p[b][1] - p[a][1], len = std::hypot(du, dv);
    double c_min = 1e9, c_sum = 0.0, s_min = 1e9, s_sum = 0.0;
    for (int s = 1; s <= kAlong; ++s) {
      const double t = static_cast<double>(s) / (kAlong + 1);
      const double c = sample_bilinear(likelihood, p[a][0] + t * du, p[a][1] + t * dv);
      const double q = sample_bilinear(anchor_score, p[a][0] + t * du, p[a][1] + t * dv);
      c_min = std::min(c_min, c), c_sum += c;
      s_min = std::min(s_min, q), s_sum += q;
    }
    const auto& ma = anchors.mean_dir[a];
    const auto& mb = anchors.mean_dir[b];
    const double ca = axis_cos(du, dv, ma), cb = axis_cos(du, dv, mb);
    const std::array<double, 2> msum{ma[0] + mb[0], ma[1] + mb[1]};
    const double na = std::hypot(ma[0], ma[1]), nb = std::hypot(mb[0], mb[1]);
    const double agree = na > 0.0 && nb > 0.0 ? (ma[0] * mb[0] + ma[1] * mb[1]) / (na * nb) : 0.0;
    const auto [conf_a, bg_a] = confidence_and_background(anchors.votes[a], ma);
    const auto [conf_b, bg_b] = confidence_and_background(anchors.votes[b], mb);
    const int ra = rank(a, b), rb = rank(b, a);
    int skipped = 0;
    for (size_t k = 0; k < n && len > 0.0; ++k) {
      if (k == a || k == b) continue;
      const double t = ((p[k][0] - p[a][0]) * du + (p[k][1] - p[a][1]) * dv) / (len * len);
      if (t <= 0.0 || t >= 1.0) continue;
      skipped += std::hypot(p[a][0] + t * du - p[k][0], p[a][1] + t * dv - p[k][1]) <= kSkipPx;
    }
    const double lo_a = nn[a] > 0.0 ? len / nn[a] : 1.0, lo_b = nn[b] > 0.0 ? len / nn[b] : 1.0;
    const double values[] = {len,
                             std::min(anchors.scores[a], anchors.scores[b]),
                             std::max(anchors.scores[a], anchors.scores[b]),
                             c_min,
                             c_sum / kAlong,
                             sample_bilinear(likelihood, p[a][0] + 0.5 * du, p[a][1] + 0.5 * dv),
                             s_min,
                             s_sum / kAlong,
                             std::min(ca, cb),
                             std::max(ca, cb),
                             axis_cos(du, dv, msum),
                             agree,
                             std::min(conf_a, conf_b),
                             std::max(bg_a, bg_b),
                             static_cast<double>(std::min(ra, rb)),
                             static_cast<double>(std::max(ra, rb)),
                             std::min(lo_a, lo_b),
                             std::max(lo_a, lo_b),
                             static_cast<double>(skipped)};
    static_assert(sizeof(values) / sizeof(values[0]) == 19, "one value per pair feature name");
    for (int c = 0; c < out.cols; ++c) out.at<float>(static_cast<int>(r), c) = static_cast<float>(values[c]);
  }
  return out;
}

graph::LaneGraph lane_graph_from_tile(const metrics::Graph& truth) {
  const metrics::CleanGraph g = metrics::clean_graph(truth);
  graph::LaneGraph out;
  for (const auto& nd : g.nodes) out.nodes.push_back({nd.u, nd.v});
  const size_t n = g.nodes.size();
  std::vector<int> in(n, 0);
  std::vector<std::vector<int32_t>> out_edges(n);
  for (size_t e = 0; e < g.edges.size(); ++e) {
    ++in[static_cast<size_t>(g.edges[e][1])];
    out_edges[static_cast<size_t>(g.edges[e][0])].push_back(static_cast<int32_t>(e));
  }
  auto pass_through = [&](size_t v) { return in[v] == 1 && out_edges[v].size() == 1; };
  std::vector<char> used(g.edges.size(), 0);
  // One chain from edge e onwards, through pass-through nodes, as a lane.
  auto chain = [&](int32_t e) {
    graph::Lane lane;
    lane.token = "chain-" + std::to_string(out.lanes.size());
    const auto li = static_cast<int32_t>(out.lanes.size());
    lane.nodes.push_back(g.edges[static_cast<size_t>(e)][0]);
    while (e >= 0 && !used[static_cast<size_t>(e)]) {
      used[static_cast<size_t>(e)] = 1;
      const auto [s, t] = g.edges[static_cast<size_t>(e)];
      out.edges.push_back({s, t, li});
      lane.length_m += out.edge_length_m(out.edges.back());
      lane.nodes.push_back(t);
      e = pass_through(static_cast<size_t>(t)) ? out_edges[static_cast<size_t>(t)][0] : -1;
    }
    out.lanes.push_back(std::move(lane));
  };
  for (size_t v = 0; v < n; ++v) {
    if (pass_through(v)) continue;
    for (int32_t e : out_edges[v]) {
      if (!used[static_cast<size_t>(e)]) chain(e);
    }
  }
  for (size_t e = 0; e < g.edges.size(); ++e) {  // closed loops of pass-through nodes
    if (!used[e]) chain(static_cast<int32_t>(e));
  }
  std::vector<std::vector<int32_t>> starting_at(n);
  for (size_t l = 0; l < out.lanes.size(); ++l) {
    starting_at[static_cast<size_t>(out.lanes[l].nodes.front())].push_back(static_cast<int32_t>(l));
  }
  for (auto& lane : out.lanes) lane.successors = starting_at[static_cast<size_t>(lane.nodes.back())];
  return out;
}

std::vector<int> connection_labels(const metrics::Graph& truth, const std::vector<std::array<double, 2>>& anchors,
                                   const std::vector<std::array<int, 2>>& pairs, const PairOptions& options) {
  std::vector<int> labels(pairs.size(), 0);
  const graph::LaneGraph lanes = lane_graph_from_tile(truth);
  if (lanes.edges.empty() || anchors.empty()) return labels;
  const graph::SegmentIndex index(lanes, 16.0);
  std::vector<graph::Node> points;
  for (const auto& a : anchors) points.push_back({a[0], a[1]});
  graph::ProjectionOptions po;
  po.max_distance_m = options.label_max_distance_px;  // the tile's lane graph is in pixels
  po.max_follow_m = options.label_max_follow_px;
  const graph::AdaptiveGroundTruth gt = graph::project_onto_lanes(lanes, index, points, po);
  std::set<std::array<int, 2>> connected;
  for (const auto& [a, b] : gt.connections) {
    const int ia = gt.points[static_cast<size_t>(a)].input, ib = gt.points[static_cast<size_t>(b)].input;
    if (ia != ib) connected.insert({std::min(ia, ib), std::max(ia, ib)});
  }
  for (size_t r = 0; r < pairs.size(); ++r) labels[r] = connected.count(pairs[r]) ? 1 : 0;
  return labels;
}

}  // namespace nsg::model

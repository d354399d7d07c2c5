#include "nsg/model/variants.h"

#include "nsg/core/error.h"

namespace nsg::model {

Variant parse_variant(const std::string& name, const std::string& field) {
  if (name == "b1") return Variant::kB1;
  if (name == "b2") return Variant::kB2;
  if (name == "graph") return Variant::kGraph;
  throw ConfigError("", field, "b1, b2 or graph (got '" + name + "')");
}

std::string to_string(Variant variant) {
  switch (variant) {
    case Variant::kB1: return "b1";
    case Variant::kB2: return "b2";
    case Variant::kGraph: return "graph";
  }
  return "b1";
}

namespace {

// Orients and scores the pairs like b1 (orient_and_score), with the anchors' own votes,
// then puts the anchor scores on the nodes.
metrics::Graph oriented(const AnchorSet& anchors, const std::vector<std::array<int, 2>>& pairs,
                        const cv::Mat& likelihood, std::vector<double>* angle_deg) {
  AnchorGraph ag;
  ag.nodes = anchors.points;
  ag.pairs = pairs;
  const DirectionVotes cached = [&](const std::vector<std::array<double, 2>>&) { return anchors.votes; };
  metrics::Graph g = orient_and_score(ag, likelihood, cached, angle_deg);
  g.node_scores = anchors.scores;
  return g;
}

}  // namespace

metrics::Graph b2_graph(const AnchorSet& anchors, const cv::Mat& likelihood, const AnchorOptions& anchor_options,
                        const ExtractionOptions& extraction) {
  anchor_options.validate();
  std::vector<double> angle_deg;
  metrics::Graph g =
      oriented(anchors, nearest_neighbour_pairs(anchors.points, anchor_options.neighbours), likelihood, &angle_deg);
  postprocess(g, likelihood.rows, extraction, &angle_deg);
  return g;
}

metrics::Graph pair_graph(const AnchorSet& anchors, const cv::Mat& likelihood, const cv::Mat& anchor_score,
                          const PairOptions& pairs, const PairScorer& scorer, const ExtractionOptions& extraction) {
  pairs.validate();
  const std::vector<std::array<int, 2>> candidates = candidate_pairs(anchors.points, pairs.radius_px);
  const std::vector<double> p =
      candidates.empty() ? std::vector<double>{} : scorer(pair_features(anchors, candidates, likelihood, anchor_score));
  NSG_CHECK(p.size() == candidates.size(), DataError, "", "pair scores", "one per candidate pair");
  std::vector<std::array<int, 2>> kept;
  std::vector<double> kept_scores;
  for (size_t k = 0; k < candidates.size(); ++k) {
    if (p[k] < pairs.min_connection_score) continue;
    kept.push_back(candidates[k]);
    kept_scores.push_back(p[k]);
  }
  std::vector<double> angle_deg;
  metrics::Graph g = oriented(anchors, kept, likelihood, &angle_deg);
  g.edge_scores = kept_scores;
  postprocess(g, likelihood.rows, extraction, &angle_deg);
  return g;
}

}  // namespace nsg::model

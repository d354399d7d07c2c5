#pragma once
// The three reference models of the paper's Table II, sharing the per-pixel features, the
// LaneDirNet head, the paper's direction rule and the post-processing:
//   b1    — skeletonized centreline regression (graph_extraction.h);
//   b2    — anchor points (anchors.h), each joined to its two nearest neighbours;
//   graph — the same anchors, candidate pairs within a radius, a trained has-connection
//           classifier (pairs.h) deciding which pairs are edges (LaneGraphNet's idea).
#include <functional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "nsg/metrics/graph.h"
#include "nsg/model/anchors.h"
#include "nsg/model/graph_extraction.h"
#include "nsg/model/pairs.h"

namespace nsg::model {

enum class Variant { kB1, kB2, kGraph };

// "b1", "b2" or "graph"; ConfigError naming `field` and the choices otherwise.
Variant parse_variant(const std::string& name, const std::string& field = "--variant");
std::string to_string(Variant variant);

// b2: anchors joined to their options.neighbours nearest anchors, oriented by the paper's
// rule, node scores = anchor scores, edge scores = mean centreline likelihood along the
// edge, then the shared post-processing.
metrics::Graph b2_graph(const AnchorSet& anchors, const cv::Mat& likelihood, const AnchorOptions& anchor_options,
                        const ExtractionOptions& extraction);

// The has-connection classifier: P(connected) per row of pair features.
using PairScorer = std::function<std::vector<double>(const cv::Mat& pair_features)>;

// graph: candidate pairs within pairs.radius_px, kept where the classifier's score is
// ≥ pairs.min_connection_score, oriented by the paper's rule, node scores = anchor scores,
// edge scores = the classifier's, then the shared post-processing.
metrics::Graph pair_graph(const AnchorSet& anchors, const cv::Mat& likelihood, const cv::Mat& anchor_score,
                          const PairOptions& pairs, const PairScorer& scorer, const ExtractionOptions& extraction);

}  // namespace nsg::model

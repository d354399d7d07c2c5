// Metrics v2 drawn from GEO/TOPO's matching and searches (docs/metrics.md "Junction TOPO"
// and "Per-class recall"): no search of their own, so they cost nothing beyond TOPO's.
#include <vector>

#include "geo_topo_samples.h"
#include "internal.h"

namespace nsg::metrics::detail {
namespace {

// Nodes with two or more outgoing edges: a lane graph's splits, where a directed search
// from the node sees more than one road ahead (the split points of SDA as well).
std::vector<char> split_nodes(const CleanGraph& g) {
  std::vector<int32_t> out_degree(g.nodes.size(), 0);
  for (const auto& e : g.edges) ++out_degree[static_cast<size_t>(e[0])];
  std::vector<char> split(g.nodes.size(), 0);
  for (size_t n = 0; n < split.size(); ++n) split[n] = out_degree[n] >= 2 ? 1 : 0;
  return split;
}

}  // namespace

// CGNet's junction TOPO: the directed TOPO terms at the seeds whose ground-truth sample is
// a split node, averaged over those seeds and scaled by GEO precision (recall) as TOPO's
// sum over all seeds is: P = (M/N_P) · mean p_s, R = (M/N_G) · mean r_s. Undefined without
// a ground-truth split; with splits but none matched, recall 0 (and precision 0, or
// undefined for an empty prediction).
void set_junction_topo(const CleanGraph& gt_graph, const SampleGraph& gt,
                       const std::vector<std::pair<int32_t, int32_t>>& seeds, const SeedTopo& directed,
                       GeoTopoResult& r) {
  const std::vector<char> split = split_nodes(gt_graph);
  bool any_split = false;
  for (const int32_t node : gt.node_of) any_split = any_split || split[static_cast<size_t>(node)] != 0;
  if (!any_split) return;
  const auto at_junction = [&](size_t s) {
    const int32_t g = seeds[s].first;
    return g < gt.n_node_samples && split[static_cast<size_t>(gt.node_of[static_cast<size_t>(g)])] != 0;
  };
  for (size_t s = 0; s < seeds.size(); ++s) r.jtopo_seeds += at_junction(s) ? 1 : 0;
  const auto m = static_cast<double>(r.matched);
  const auto np = static_cast<double>(r.pred_samples), ng = static_cast<double>(r.gt_samples);
  if (r.jtopo_seeds == 0) {
    r.jtopo_precision = ratio(0.0, np);
    r.jtopo_recall = 0.0;
  } else {
    const auto nj = static_cast<double>(r.jtopo_seeds);
    r.jtopo_precision = ratio(m * (seed_sum(directed.p, at_junction) / nj), np);
    r.jtopo_recall = ratio(m * (seed_sum(directed.r, at_junction) / nj), ng);
  }
  r.jtopo_f1 = f1_of(r.jtopo_precision, r.jtopo_recall);
}

// Per class c: GEO recall = the class's GT samples that are matched / the class's GT samples;
// TOPO recall = Σ r_s over the seeds on the class / the class's GT samples (TOPO recall's
// rule 7 restricted to the class). Undefined when the ground truth has no flags or no
// sample of the class.
void set_class_recalls(const SampleGraph& gt, const std::vector<int32_t>& match_of_g,
                       const std::vector<std::pair<int32_t, int32_t>>& seeds, const SeedTopo& undirected,
                       GeoTopoResult& r) {
  if (gt.classes.empty()) return;
  for (int c = 0; c < kEdgeClassCount; ++c) {
    const auto bit = static_cast<uint8_t>(1u << c);
    int64_t n = 0, matched = 0;
    for (size_t x = 0; x < gt.size(); ++x) {
      if ((gt.classes[x] & bit) == 0) continue;
      ++n;
      matched += match_of_g[x] >= 0 ? 1 : 0;
    }
    r.gt_samples_by_class[c] = n;
    r.matched_by_class[c] = matched;
    const auto in_class = [&](size_t s) { return (gt.classes[static_cast<size_t>(seeds[s].first)] & bit) != 0; };
    r.geo_recall_by_class[c] = ratio(static_cast<double>(matched), static_cast<double>(n));
    r.topo_recall_by_class[c] = ratio(seed_sum(undirected.r, in_class), static_cast<double>(n));
  }
}

}  // namespace nsg::metrics::detail

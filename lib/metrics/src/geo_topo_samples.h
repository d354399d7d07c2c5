#pragma once
// GEO/TOPO sampling, internal to the metrics module: the sample graphs of rules 2-3 and the
// sorted GEO candidate pairs of rule 4 (geo_topo_samples.cpp), read by the matching and
// the radius searches of rules 4-8 (geo_topo.cpp). Rule numbers refer to docs/metrics.md
// "GEO and TOPO".
#include <cstdint>
#include <utility>
#include <vector>

#include "internal.h"

namespace nsg::metrics::detail {

// One segment's run of samples (rule 3): end samples a (node i) and b (node j), interior
// samples first .. first + k - 2 from the a end, k pieces of length w.
struct Chain {
  int32_t a, b, first, k;
  double w;
  bool fwd, bwd;  // traversable a -> b, b -> a on the directed sample graph
};

// Samples of a graph (rule 2) and its sample graph (rule 3) stored as chains between node
// samples, so radius searches run Dijkstra over nodes only and walk the chains.
struct SampleGraph {
  std::vector<Point> pos;
  int32_t n_node_samples = 0;         // samples 0 .. n-1 are nodes
  std::vector<Chain> chains;          // by increasing (i, j)
  std::vector<int32_t> chain_offset;  // CSR: chains incident to each node sample
  std::vector<int32_t> chain_ids;
  std::vector<int32_t> chain_of_interior;  // interior sample - n_node_samples -> chain
  std::vector<int32_t> comp;               // connected component (a root sample) of each sample
  std::vector<int32_t> node_of;            // node sample -> the cleaned graph's node index
  // EdgeClass bits of each sample (metrics v2): an interior sample's are its segment's, a
  // node sample's those of every segment at it. Empty when the graph has no edge flags.
  std::vector<uint8_t> classes;
  std::vector<uint8_t> flags;  // EdgeFlag bits likewise (the change labels' kinds); empty likewise

  size_t size() const { return pos.size(); }
};

// The samples of `g` every <= step_px along each segment (rule 2) and their sample graph
// (rule 3).
SampleGraph sample_graph(const CleanGraph& g, double step_px);

struct Candidate {
  int64_t q;
  int32_t g, p;
};

// All pairs within the match radius, sorted by (q, g, p) (rule 4). Pred samples are
// bucketed on a grid of the match radius so only neighbouring cells are tested.
std::vector<Candidate> candidates(const SampleGraph& gt, const SampleGraph& pred, double match_px);

// TOPO's per-seed values (rule 7's p_s and r_s), by seed index.
struct SeedTopo {
  std::vector<double> p, r;
};
// The sum of values[s] over the seeds s that `keep` accepts, in seed order (rule 7's order).
template <class Keep>
double seed_sum(const std::vector<double>& values, const Keep& keep) {
  double sum = 0.0;
  for (size_t s = 0; s < values.size(); ++s)
    if (keep(s)) sum += values[s];
  return sum;
}

// Metrics v2 from the same matching and searches (geo_topo_v2.cpp, docs/metrics.md
// "Junction TOPO" and "Per-class recall"): JTOPO from the directed per-seed values at the
// seeds on ground-truth split nodes; GEO and TOPO recall per edge class from the
// undirected ones.
void set_junction_topo(const CleanGraph& gt_graph, const SampleGraph& gt,
                       const std::vector<std::pair<int32_t, int32_t>>& seeds, const SeedTopo& directed,
                       GeoTopoResult& r);
void set_class_recalls(const SampleGraph& gt, const std::vector<int32_t>& match_of_g,
                       const std::vector<std::pair<int32_t, int32_t>>& seeds, const SeedTopo& undirected,
                       GeoTopoResult& r);

}  // namespace nsg::metrics::detail

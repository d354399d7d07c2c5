#include "nsg/metrics/graph.h"

#include <algorithm>
#include <set>

#include "nsg/core/error.h"

namespace nsg::metrics {

CleanGraph clean_graph(const Graph& graph) {
  CleanGraph out;
  out.nodes = graph.nodes;
  const auto n = static_cast<int64_t>(graph.nodes.size());
  std::set<std::array<int32_t, 2>> seen;
  for (size_t k = 0; k < graph.edges.size(); ++k) {
    const auto [i, j] = graph.edges[k];
    NSG_CHECK(i >= 0 && i < n && j >= 0 && j < n, DataError, "", "edges/" + std::to_string(k),
              "node indices in [0, " + std::to_string(n) + ")");
    if (i == j) {
      ++out.self_loops_dropped;
      continue;
    }
    const std::array<int32_t, 2> e{static_cast<int32_t>(i), static_cast<int32_t>(j)};
    if (!seen.insert(e).second) {
      ++out.duplicate_edges_dropped;
      continue;
    }
    out.edges.push_back(e);
  }
  return out;
}

std::vector<Segment> segments_of(const CleanGraph& graph) {
  std::vector<Segment> segs;
  segs.reserve(graph.edges.size());
  for (const auto& [i, j] : graph.edges) {
    Segment s;
    s.i = std::min(i, j);
    s.j = std::max(i, j);
    s.fwd = i < j;
    s.bwd = i > j;
    segs.push_back(s);
  }
  std::sort(segs.begin(), segs.end(),
            [](const Segment& a, const Segment& b) { return a.i != b.i ? a.i < b.i : a.j < b.j; });
  std::vector<Segment> merged;
  for (const Segment& s : segs) {
    if (!merged.empty() && merged.back().i == s.i && merged.back().j == s.j) {
      merged.back().fwd = merged.back().fwd || s.fwd;
      merged.back().bwd = merged.back().bwd || s.bwd;
    } else {
      merged.push_back(s);
    }
  }
  return merged;
}

}  // namespace nsg::metrics

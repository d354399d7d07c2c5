#include "nsg/metrics/graph.h"

#include <algorithm>
#include <set>

#include "nsg/core/error.h"

namespace nsg::metrics {

uint8_t class_mask_of(uint8_t edge_flags) {
  const int kind = (edge_flags & kEdgeConnector) != 0 ? kClassConnector : kClassLane;
  const int place = (edge_flags & kEdgeInIntersection) != 0 ? kClassInIntersection : kClassOutsideIntersection;
  // Changed = a centreline the prior did not have there (added, moved; removed on a prior
  // graph); a retype changes the paint, not the centreline, so it is unchanged here.
  unsigned change = 0;
  if ((edge_flags & (kEdgeAdded | kEdgeMoved | kEdgeRemoved)) != 0) change = 1u << kClassChanged;
  else if ((edge_flags & (kEdgeUnchanged | kEdgeRetyped)) != 0) change = 1u << kClassUnchanged;
  return static_cast<uint8_t>((1u << kind) | (1u << place) | change);
}

CleanGraph clean_graph(const Graph& graph) {
  CleanGraph out;
  out.nodes = graph.nodes;
  const auto n = static_cast<int64_t>(graph.nodes.size());
  const bool flagged = !graph.edge_flags.empty();
  NSG_CHECK(!flagged || graph.edge_flags.size() == graph.edges.size(), DataError, "", "edge_flags",
            "one flag byte per edge");
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
    if (flagged) out.edge_flags.push_back(graph.edge_flags[k]);
  }
  return out;
}

std::vector<Segment> segments_of(const CleanGraph& graph) {
  std::vector<Segment> segs;
  segs.reserve(graph.edges.size());
  for (size_t k = 0; k < graph.edges.size(); ++k) {
    const auto [i, j] = graph.edges[k];
    Segment s;
    if (!graph.edge_flags.empty()) {
      s.classes = class_mask_of(graph.edge_flags[k]);
      s.flags = graph.edge_flags[k];
    }
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
      merged.back().classes |= s.classes;
      merged.back().flags |= s.flags;
    } else {
      merged.push_back(s);
    }
  }
  return merged;
}

}  // namespace nsg::metrics

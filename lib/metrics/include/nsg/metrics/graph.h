#pragma once
// Lane graphs as the scorer sees them: nodes in pixel coordinates of a 256 x 256 tile
// (integer = pixel centre) and directed edges between node indices (docs/metrics.md).
#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace nsg::metrics {

struct Point {
  double u = 0.0;  // column, px
  double v = 0.0;  // row, px
};

struct Graph {
  std::vector<Point> nodes;
  std::vector<std::array<int64_t, 2>> edges;  // directed i -> j, node indices
  std::vector<double> node_scores;            // optional, empty if absent
  std::vector<double> edge_scores;            // optional, empty if absent
};

// Tile key -> graph, sorted by key (the order of every reduction).
using GraphSet = std::map<std::string, Graph>;

// A graph after dropping self-loops and duplicate directed edges (docs/metrics.md
// "Cleaning"), with how many of each were dropped.
struct CleanGraph {
  std::vector<Point> nodes;
  std::vector<std::array<int32_t, 2>> edges;  // first occurrence order kept
  int64_t self_loops_dropped = 0;
  int64_t duplicate_edges_dropped = 0;
};

// Throws DataError if an edge index is out of range (submissions are validated first).
CleanGraph clean_graph(const Graph& graph);

// Undirected segment {i, j} (i < j) with the directions present (docs/metrics.md GEO/TOPO
// rule 1), sorted by (i, j).
struct Segment {
  int32_t i = 0;
  int32_t j = 0;
  bool fwd = false;  // edge i -> j exists
  bool bwd = false;  // edge j -> i exists
};
std::vector<Segment> segments_of(const CleanGraph& graph);

}  // namespace nsg::metrics

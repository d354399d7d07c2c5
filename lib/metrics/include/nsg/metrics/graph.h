#pragma once
// Lane graphs as the scorer sees them: nodes in pixel coordinates of a 256 x 256 tile
// (integer = pixel centre) and directed edges between node indices (docs/metrics.md).
#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace nsg::metrics {

struct Point {
  double u = 0.0;  // column, px
  double v = 0.0;  // row, px
};

// What a ground-truth edge is (graph.json's edge attributes, docs/dataset-format.md "Graph
// attributes"), as bit flags per edge: the per-class recalls of docs/metrics.md "Metrics v2"
// read them. Submissions carry none.
enum EdgeFlag : uint8_t {
  kEdgeConnector = 1,       // kind "connector" (else a lane)
  kEdgeInIntersection = 2,  // in_intersection
  // A map-update tile's change label (graph.json's "change", docs/metrics.md "Map change"):
  // at most one; none of them when the graph has no labels.
  kEdgeUnchanged = 4,
  kEdgeAdded = 8,
  kEdgeRemoved = 16,  // on a prior graph's edges only: the lane is gone from the current map
  kEdgeMoved = 32,
  kEdgeRetyped = 64,
};
inline constexpr uint8_t kEdgeChangeLabels = kEdgeUnchanged | kEdgeAdded | kEdgeRemoved | kEdgeMoved | kEdgeRetyped;

struct Graph {
  std::vector<Point> nodes;
  std::vector<std::array<int64_t, 2>> edges;  // directed i -> j, node indices
  std::vector<double> node_scores;            // optional, empty if absent
  std::vector<double> edge_scores;            // optional, empty if absent
  std::vector<uint8_t> edge_flags;            // optional, EdgeFlag bits per edge; empty if unknown
  // A map-update ground truth's prior graph (the map before the change, clipped to the same
  // tile, its edges labelled), which the change metrics compare with; null elsewhere.
  std::shared_ptr<const Graph> prior;
};

// Tile key -> graph, sorted by key (the order of every reduction).
using GraphSet = std::map<std::string, Graph>;

// A graph after dropping self-loops and duplicate directed edges (docs/metrics.md
// "Cleaning"), with how many of each were dropped.
struct CleanGraph {
  std::vector<Point> nodes;
  std::vector<std::array<int32_t, 2>> edges;  // first occurrence order kept
  std::vector<uint8_t> edge_flags;            // per kept edge when the graph had them, else empty
  int64_t self_loops_dropped = 0;
  int64_t duplicate_edges_dropped = 0;
};

// Throws DataError if an edge index is out of range (submissions are validated first).
CleanGraph clean_graph(const Graph& graph);

// The edge classes of the per-class recalls (docs/metrics.md "Per-class recall"), as bits of a
// membership mask: a lane or a connector, inside or outside an intersection, and on a
// map-update tile changed (a centreline added or moved) or unchanged (unchanged or retyped:
// the same centreline).
enum EdgeClass : int {
  kClassLane,
  kClassConnector,
  kClassInIntersection,
  kClassOutsideIntersection,
  kClassChanged,
  kClassUnchanged,
  kEdgeClassCount
};
// The classes an edge with these EdgeFlag bits belongs to (one of each pair; of the last
// pair none when the edge has no change label).
uint8_t class_mask_of(uint8_t edge_flags);

// Undirected segment {i, j} (i < j) with the directions present (docs/metrics.md GEO/TOPO
// rule 1), sorted by (i, j).
struct Segment {
  int32_t i = 0;
  int32_t j = 0;
  bool fwd = false;     // edge i -> j exists
  bool bwd = false;     // edge j -> i exists
  uint8_t classes = 0;  // EdgeClass bits of the edges it merges; 0 when the graph has no flags
  uint8_t flags = 0;    // EdgeFlag bits of the edges it merges (their union)
};
std::vector<Segment> segments_of(const CleanGraph& graph);

}  // namespace nsg::metrics

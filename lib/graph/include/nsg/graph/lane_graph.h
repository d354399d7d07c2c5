#pragma once
// The directed lane graph of one location (docs/architecture.md): every lane and lane
// connector discretized exactly like the devkit, joined per lane without duplicated joint
// poses, resampled along arc length to evenly spaced nodes at most `max_spacing_m` apart,
// and joined across connectivity (the end node of A is the start node of B).
#include <cstdint>
#include <string>
#include <vector>

#include "nsg/core/issues.h"
#include "nsg/geometry/arcline.h"

namespace nsg::options {
template <typename Owner>
class Table;  // nsg/core/options.h
}

namespace nsg::graph {

// One lane or lane connector as the map gives it (reader-independent, so tests can build
// analytic maps without JSON).
struct LaneSource {
  std::string token;
  bool is_connector = false;
  std::vector<geometry::ArclinePath> paths;  // arcline_path_3[token]
  bool has_connectivity = true;              // token present in `connectivity`
  std::vector<std::string> outgoing;
  std::vector<std::string> incoming;
};

struct LaneGraphOptions {
  double max_spacing_m = 2.0;        // cap on the distance between consecutive nodes
  double source_resolution_m = 0.5;  // devkit discretization before resampling
  double join_tolerance_m = 0.05;    // lane ends closer than this become one node
  bool strict = false;               // map defects become errors
  void validate() const;             // the declared checks; ConfigError naming the key
};
// The config keys graph.* (nsg/core/options.h).
const options::Table<LaneGraphOptions>& lane_graph_option_table();

// Where lanes fork or join, from the node's successor edges (lane changes do not count):
// split = two or more edges leave it, merge = two or more arrive, both = both.
enum class Junction : uint8_t { kNone, kSplit, kMerge, kBoth };
// The turn a lane or connector makes (lane_attributes.h says the rule).
enum class Turn : uint8_t { kStraight, kLeft, kRight, kUTurn };

struct Node {
  double x_m = 0.0;
  double y_m = 0.0;
  Junction junction = Junction::kNone;  // set by add_lane_attributes
};

struct Edge {
  int32_t source = -1;  // node index
  int32_t target = -1;
  int32_t lane = -1;  // index into LaneGraph::lanes
};

struct Lane {
  std::string token;
  bool is_connector = false;
  double length_m = 0.0;            // polyline length of the joined discretization
  std::vector<int32_t> nodes;       // node chain from start to end (after joining)
  std::vector<int32_t> successors;  // lane indices from `outgoing` that resolved
  // Attributes (lane_attributes.h): set by add_lane_attributes and mark_intersections.
  Turn turn = Turn::kStraight;
  bool in_intersection = false;  // its middle lies in a road_segment marked is_intersection
};

// A lateral move between neighbouring lanes of one direction: from a node of one lane to
// the nearest node of the lane beside it (lane_attributes.h says the rule). Kept apart
// from the successor edges, so that a reader of `edges` sees the same graph as before.
struct LaneChange {
  int32_t source = -1;  // node index
  int32_t target = -1;
  int32_t source_lane = -1;  // index into LaneGraph::lanes
  int32_t target_lane = -1;
};

struct LaneGraph {
  std::vector<Node> nodes;
  std::vector<Edge> edges;               // lane by lane, in lane order, from start to end
  std::vector<Lane> lanes;               // input order (lanes then connectors, as the map lists them)
  std::vector<LaneChange> lane_changes;  // by source node, then target node

  double edge_length_m(const Edge& e) const;
  double max_edge_length_m() const;
  // Lane index of a token, or −1.
  int32_t find_lane(const std::string& token) const;
};

// Builds the graph. Map defects (dangling connectivity, unmirrored incoming/outgoing,
// lanes without paths, ends farther apart than the tolerance) are added to `issues` as
// warnings, isolated lanes as infos (checks "graph.*"). Edges to unknown tokens are left
// out, every other edge kept. With options.strict the first warning throws DataError
// naming `map_label` and the token.
LaneGraph build_lane_graph(const std::vector<LaneSource>& sources, const LaneGraphOptions& options, Issues* issues,
                           const std::string& map_label = "");

// --strict: throws DataError(map_label, subject, …) naming the first issue that is not an
// info and how many there are; returns if all are infos.
void throw_if_defects(const std::vector<Issue>& found, const std::string& map_label);

// Points of a polyline resampled along its arc length into n = ceil(length / max_spacing) + 1
// evenly spaced points (n ≥ 2), first and last kept exactly.
std::vector<Node> resample_polyline(const std::vector<Node>& polyline, double max_spacing_m);

// The joined centerline of one lane: devkit discretization of each path, without the
// repeated joint pose between consecutive paths.
std::vector<Node> joined_centerline(const std::vector<geometry::ArclinePath>& paths, double resolution_m);

}  // namespace nsg::graph

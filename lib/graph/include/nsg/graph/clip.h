#pragma once
// Clipping the lane graph to an axis-aligned tile (docs/architecture.md; docs/dataset-format.md for the pixel
// coordinates): edges inside are kept, an edge crossing the border is cut at the border
// with a new node there, direction is kept.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "nsg/graph/lane_graph.h"
#include "nsg/graph/segment_index.h"

namespace nsg::graph {

// A tile in map metres. The box is closed: a lane lying exactly on the border belongs to
// every tile that shares that border.
struct TileBounds {
  double x_west_m = 0.0;
  double y_south_m = 0.0;
  double x_east_m = 0.0;
  double y_north_m = 0.0;
};

struct TileNode {
  int32_t id = 0;
  double u_px = 0.0;  // (x − x_west) / resolution − 0.5: integer = pixel centre
  double v_px = 0.0;  // (y_north − y) / resolution − 0.5: row 0 = north
  double x_m = 0.0;
  double y_m = 0.0;
  Junction junction = Junction::kNone;  // the lane graph's; kNone for a node made at the border
};

// What became of a lane between a prior map and the current one (generate's map-update
// preset, map_changes.h): kNone outside such a dataset.
enum class MapChange : uint8_t { kNone, kUnchanged, kAdded, kRemoved, kMoved, kRetyped };
const char* map_change_name(MapChange change);  // "unchanged", "added", … ("" for kNone)
bool map_change_from_name(const std::string& name, MapChange* change);

// A successor edge with its lane's attributes (lane_attributes.h).
struct TileEdge {
  int32_t source = 0;
  int32_t target = 0;
  std::string lane_token;
  bool is_connector = false;  // graph.json "kind": "connector" (else "lane")
  bool in_intersection = false;
  Turn turn = Turn::kStraight;
  MapChange change = MapChange::kNone;  // graph.json "change" (map-update datasets)
};

// A lane change between two nodes of the tile (both ends inside it).
struct TileLaneChange {
  int32_t source = 0;
  int32_t target = 0;
  std::string from_lane_token, to_lane_token;
};

struct TileGraph {
  std::vector<TileNode> nodes;
  std::vector<TileEdge> edges;
  std::vector<TileLaneChange> lane_changes;  // by source, then target node
  // False when read from a graph.json written before the edge attributes (an edge without
  // "kind"): its kind and in_intersection are then defaults, not facts.
  bool has_edge_attributes = true;
  double total_length_m() const;
};

// Clips `graph` to `bounds`. Node ids are dense 0..n−1 in order of first use while edges
// are visited in graph order, so the result is deterministic. A lane change is kept when
// both its nodes are nodes of the clipped edges (it is never cut at the border).
TileGraph clip_to_tile(const LaneGraph& graph, const SegmentIndex& index, const TileBounds& bounds,
                       double resolution_m = 0.2);

// Liang–Barsky: the parameter range [t0, t1] of segment a→b inside the closed box, or
// false when it misses (or only touches a single point).
bool clip_segment(double ax, double ay, double bx, double by, const TileBounds& box, double* t0, double* t1);

}  // namespace nsg::graph

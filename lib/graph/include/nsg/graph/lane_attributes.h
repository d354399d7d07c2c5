#pragma once
// What a planner asks of a lane graph beyond its geometry (docs/dataset-format.md "Graph
// attributes"): the turn each lane or connector makes, whether it lies in an intersection,
// which nodes are forks and joins, and where a vehicle may change lanes.
#include <string>

#include "nsg/graph/lane_graph.h"
#include "nsg/nuscenes/map_expansion.h"

namespace nsg::graph {

// The turn rule: Δ is the signed change of heading from a lane's first segment to its last
// (counter-clockwise positive, wrapped into (−180°, 180°]); |Δ| ≤ 30° is straight, |Δ| ≥ 150°
// a U-turn, otherwise left for Δ > 0 and right for Δ < 0. Measured on the graph's resampled
// nodes, which follow the devkit's discretization of the arclines.
inline constexpr double kStraightMaxDeg = 30.0;
inline constexpr double kUTurnMinDeg = 150.0;

// The lane-change rule, from geometry (the same on every map: it needs no shared divider
// tokens, which the synthetic maps do not have): a node of lane A has an edge to lane B when
// neither is a connector, the nearest point of B's centreline lies 2 to 5 m from the node
// (one lane width in nuScenes, not two), inside B (not at its start or end), and B runs
// within 20° of A's heading there (so never the opposite direction). The edge goes to B's
// node nearest that point; one edge per node and neighbouring lane. The dividers' paint
// (solid or dashed) is not read: an edge says "beside", not "allowed".
inline constexpr double kLaneChangeMinOffsetM = 2.0;
inline constexpr double kLaneChangeMaxOffsetM = 5.0;
inline constexpr double kLaneChangeMaxHeadingDeg = 20.0;

// Turn of each lane, junction of each node, and the lane changes (graph.lane_changes,
// sorted by source then target node). Deterministic; the successor edges are unchanged.
void add_lane_attributes(LaneGraph& graph);

// in_intersection of each lane: its middle node lies inside the polygon (holes excluded) of
// a road_segment marked is_intersection. Lanes of tokens the map does not know stay false.
void mark_intersections(LaneGraph& graph, const nuscenes::MapExpansion& map);

// The attribute values as graph.json writes them.
const char* turn_name(Turn turn);              // "straight", "left", "right", "u_turn"
const char* junction_name(Junction junction);  // "none", "split", "merge", "both"
// Back from the names; false for any other text.
bool turn_from_name(const std::string& name, Turn* turn);
bool junction_from_name(const std::string& name, Junction* junction);

}  // namespace nsg::graph

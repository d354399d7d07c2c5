#pragma once
// Lane sources from a loaded map expansion: every lane then every lane connector, in
// file order, with their arcline paths and connectivity.
#include <vector>

#include "nsg/graph/lane_graph.h"
#include "nsg/nuscenes/map_expansion.h"

namespace nsg::graph {

std::vector<LaneSource> lane_sources(const nuscenes::MapExpansion& map);

// build_lane_graph over lane_sources(map), after the map's own load defects
// (map.issues(), appended first to `issues`); defects name the map file. The graph comes
// with its attributes (add_lane_attributes, mark_intersections: lane_attributes.h).
LaneGraph build_lane_graph(const nuscenes::MapExpansion& map, const LaneGraphOptions& options, Issues* issues);

}  // namespace nsg::graph

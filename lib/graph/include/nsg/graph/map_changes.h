#pragma once
// A map-update dataset's change labels (generate's splits.preset map-update,
// docs/generating.md "Map update"): what became of every lane and lane connector between a
// prior map and the current one, by token. The rule works on any two versions of a map
// expansion — the synthetic release's prior and current maps, or two real map versions.
#include <map>
#include <string>

#include "nsg/graph/clip.h"
#include "nsg/nuscenes/map_expansion.h"

namespace nsg::graph {

// A centreline moved when any arcline path's pose or length differs by more than this.
inline constexpr double kMovedToleranceM = 1e-3;

// Per token of either map's lanes and connectors: added (current only), removed (prior
// only), moved (its arcline paths differ), retyped (its divider segments' types differ),
// unchanged.
std::map<std::string, MapChange> lane_changes_between(const nuscenes::MapExpansion& prior,
                                                      const nuscenes::MapExpansion& current);

// Each edge's `change` from its lane token's label (kNone when the token has none).
void label_map_changes(TileGraph& graph, const std::map<std::string, MapChange>& labels);

}  // namespace nsg::graph

#pragma once
// A tile's graph (clipped, each edge carrying its lane token) back into lanes, so the
// adaptive ground truth (project_onto_lanes) can run on one tile — what a training loop
// has at hand (the Python binding's adaptive_ground_truth).
#include "nsg/graph/clip.h"
#include "nsg/graph/lane_graph.h"

namespace nsg::graph {

enum class TileFrame { kMetres, kPixels };

// Each maximal chain of one lane token's edges becomes a lane (a lane clipped into several
// pieces gives several lanes with the same token; lanes in order of their first edge).
// Lane B is a successor of lane A when A ends at B's start node: joins across connectivity
// share a node in the tile graph. Node coordinates are (x, y) metres or, with kPixels,
// (u, v) pixels (then distances in ProjectionOptions are pixels too). Throws DataError
// naming the edge when it refers to a node that does not exist. `tile_edge_of`, when
// given, receives for each edge of the result the index of its edge in `tile`. The tile's
// lane changes become the result's, by node (their lanes −1).
LaneGraph lane_graph_from_tile(const TileGraph& tile, TileFrame frame = TileFrame::kMetres,
                               std::vector<int32_t>* tile_edge_of = nullptr);

}  // namespace nsg::graph

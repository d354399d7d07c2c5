#pragma once
// A tile's <key>.graph.json (docs/dataset-format.md): its one writer (generate) and its one
// reader, back into the graph module's type, node ids turned into indices.
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "nsg/core/issues.h"
#include "nsg/graph/clip.h"

namespace nsg::io {

// {schema_version, key, nodes: [{id, u, v, x, y, junction}], edges: [{source, target,
// lane_token, kind, in_intersection, turn}], lane_changes: [{source, target, from_lane_token,
// to_lane_token}]}; the attributes and lane_changes are optional when read (a graph written
// before them reads with their defaults).
// TileNode::id keeps the file's id; TileEdge source/target are node indices. Throws
// DataError naming `file` and the JSON path on a missing field, a non-finite number, a
// repeated node id or an edge to an unknown id. With `problems`, the reference problems
// are listed there instead ("graph.indices": a repeated id, an edge end naming no node;
// "graph.lane_changes": a lane change end naming no node; subject "file:/path"), the edge
// or lane change left out, and every problem of the document is reported in one pass
// (`validate` reads graphs this way, after the schema has checked their shape).
graph::TileGraph tile_graph_from_json(const nlohmann::json& doc, const std::string& file, Issues* problems = nullptr);

// A map-update tile's prior graph (the member "prior": {nodes, edges, lane_changes}, the
// prior map clipped to the tile, docs/dataset-format.md), read as tile_graph_from_json reads
// the graph (paths under "/prior"); nullopt when the document has none.
std::optional<graph::TileGraph> tile_prior_graph_from_json(const nlohmann::json& doc, const std::string& file,
                                                           Issues* problems = nullptr);

// The document generate writes for tile `key` (compact, a final newline): edges name their
// nodes by TileNode::id, an edge's "change" is written when it has one, and `prior` (a
// map-update tile's) goes under "prior". Reading it back gives `graph` (and `prior`) again.
std::string tile_graph_text(const std::string& key, const graph::TileGraph& graph,
                            const graph::TileGraph* prior = nullptr);

}  // namespace nsg::io

"""nsgraph.adaptive_ground_truth: the paper's adaptive graph resampling (graph:: projection
in C++)."""
import numpy as np

from . import _nsgraph
from .scoring import as_pairs, graph_arrays


def adaptive_ground_truth(tile_graph, proposals, frame="px", max_distance=None, max_follow=None,
                          resolution_m=0.2):
    """Projects proposed anchors onto the tile's ground-truth lanes (the paper's adaptive
    ground truth): each proposal goes orthogonally onto its nearest lane segment (within
    ``max_distance``), projections are ordered along each lane, consecutive ones are
    connected, and the last one of a lane connects to the first one reachable through lane
    joins (within ``max_follow`` of lanes without projections).

    tile_graph: a dataset tile or its ``graph`` dict (nodes_px / nodes_m, edges,
    lane_tokens). proposals: (M, 2) in ``frame`` "px" (u, v) or "m" (x, y).
    max_distance / max_follow default to 4 m / 20 m (in pixels: / resolution_m).

    Returns {points (K, 2) projected, in the same frame; input (K,) proposal index;
    edge (K,) index of the tile graph edge hit; lane (K,) lane piece index; lane_tokens
    [K]; along (K,) distance from the lane piece's start; distance (K,) from the proposal;
    edges (C, 2) int64 connections between points (the has-connection labels);
    lane_changes (L, 2) int64 lateral links between points, apart from the connections (a
    lane change is no successor): for each of the tile's lane changes s -> t, the point
    nearest node s among those on an edge at s to the point nearest t among those on an
    edge at t, each pair once; empty when the graph has no ``lane_changes``}.
    Points are ordered by lane piece, then along it.
    """
    if isinstance(tile_graph, dict) and isinstance(tile_graph.get("graph"), dict):
        tile_graph = tile_graph["graph"]
    if frame not in ("px", "m"):
        raise ValueError(f"frame: expected 'px' or 'm', got {frame!r}")
    scale = 1.0 / resolution_m if frame == "px" else 1.0
    nodes_name = "nodes_px" if frame == "px" else "nodes_m"
    nodes = tile_graph[nodes_name] if nodes_name in tile_graph else tile_graph["nodes"]
    nodes, edges = graph_arrays((nodes, tile_graph["edges"]))
    tokens = [str(t) for t in tile_graph.get("lane_tokens", ["lane"] * len(edges))]
    lane_changes = as_pairs(tile_graph.get("lane_changes", np.zeros((0, 2), np.int64)), np.int64)
    proposals = as_pairs(proposals, np.float64)
    return _nsgraph.adaptive_ground_truth(
        nodes, edges, tokens, lane_changes, proposals,
        (4.0 * scale) if max_distance is None else float(max_distance),
        (20.0 * scale) if max_follow is None else float(max_follow))

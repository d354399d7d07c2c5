"""nsgraph.graphify: a centreline probability map or a binary mask → its lane graph
(skeleton::graphify in C++, the rule of ``nsgraph graphify``; docs/graphify.md)."""
import os

import numpy as np

from . import _nsgraph


def graphify(map_or_path, heading=None, **options):
    """The lane graph of one tile's map, by the skeleton rule: smooth, threshold, drop
    small blobs, thin, trace, prune spurs, anchors at most ``anchor_spacing_px`` apart.

    map_or_path: a 2-D numpy array (float32 likelihoods; uint8 / uint16 scaled by 255 /
    65535, or a 0/1 mask; bool as 0/1) or the path of a PNG, GeoTIFF or .npy file.
    heading: None (undirected), or the tile's heading map for directed output — a 2-D
    float32 array or a GeoTIFF / .npy path, the direction of travel as a fraction of a turn
    clockwise from map north in [0, 1), negative where unknown (the dataset's vehicle
    layer), the map's size.
    options: ``threshold``, ``smooth_sigma_px``, ``min_component_px``, ``min_spur_px``,
    ``simplify_tolerance_px``, ``anchor_spacing_px``, ``split_crossings``,
    ``crossing_tolerance_deg``, ``crossing_merge_px``, ``heading_window_px``
    (``nsgraph graphify --list-options``).

    Returns {nodes (N, 2) float64 pixel u, v; edges (E, 2) int64; node_scores (N,) the
    likelihood at each node; edge_scores (E,) the mean likelihood along each edge}.
    Undirected, each edge given in both directions; with a heading, each edge oriented by
    the headings near its ends (both directions where none is known). Raises
    nsgraph.DataError / ParseError / IoError naming the file, ConfigError naming the option.
    """
    if heading is not None and not isinstance(heading, (str, bytes, os.PathLike)):
        heading = np.asarray(heading)
        if not heading.dtype.isnative:
            heading = heading.astype(heading.dtype.newbyteorder("="))
    elif heading is not None:
        heading = os.fsdecode(heading)
    if isinstance(map_or_path, (str, bytes, os.PathLike)):
        return _nsgraph.graphify_file(os.fsdecode(map_or_path), heading, options)
    array = np.asarray(map_or_path)
    if array.dtype == np.bool_:
        array = array.astype(np.uint8)
    elif not array.dtype.isnative:
        array = array.astype(array.dtype.newbyteorder("="))
    return _nsgraph.graphify_array(array, heading, options)

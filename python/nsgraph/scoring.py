"""Scoring and submissions: nsgraph.score (= ``nsgraph score``), score_tile,
write_submission, check_submission. The metrics, the checks and the writer are the C++
library's; this module only converts arguments."""
import json
import os

import numpy as np

from . import _nsgraph
from .errors import SubmissionError

# Every metric of a score report ({name, unit, lower_is_better, description}, report order)
# and the headline ones, from the C++ declaration (metrics::metric_info, headline_metrics).
METRICS = _nsgraph.METRICS
HEADLINE_METRICS = _nsgraph.HEADLINE_METRICS

SCHEMAS_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "schemas")
MEMORY_LABEL = "<memory>"


def graph_arrays(graph):
    """(nodes float64 (N, 2) pixel u, v; edges int64 (E, 2)) of a graph given as a dataset
    tile (or its ``graph``: nodes_px), a submission tile ({nodes, edges}) or a pair
    (nodes, edges)."""
    if isinstance(graph, dict):
        if "graph" in graph and isinstance(graph["graph"], dict):
            graph = graph["graph"]
        nodes = graph["nodes_px"] if "nodes_px" in graph else graph["nodes"]
        edges = graph["edges"]
    else:
        nodes, edges = graph
    return as_pairs(nodes, np.float64), as_pairs(edges, np.int64)


def as_pairs(values, dtype):
    """A contiguous array of the dtype; an empty one as (0, 2). Other shapes pass as they are
    for the C++ side to refuse by name."""
    if np.issubdtype(dtype, np.integer):
        # Float indices would be truncated silently by the cast (0.7 -> 0): refused instead.
        raw = np.asarray(values)
        if raw.dtype.kind == "f" and raw.size and not np.all(np.isfinite(raw) & (raw == np.floor(raw))):
            from .errors import DataError
            raise DataError(f"edges: integer node indices expected, got {raw[raw != np.floor(raw)][:1].tolist()}")
    a = np.asarray(values, dtype=dtype)
    return np.zeros((0, 2), dtype) if a.size == 0 else np.ascontiguousarray(a)


def edge_flags(graph):
    """The ground truth's edge classes as the scorer's flag bytes (_nsgraph.EDGE_FLAGS: 1
    connector, 2 inside an intersection, and on a map-update tile its change label: 4
    unchanged, 8 added, 16 removed, 32 moved, 64 retyped) from a dataset tile's graph (its
    ``connector``, ``in_intersection`` and ``change``), or an empty list when the graph has no
    edge attributes (the per-class recalls are then undefined)."""
    if isinstance(graph, dict) and "graph" in graph and isinstance(graph["graph"], dict):
        graph = graph["graph"]
    if not (isinstance(graph, dict) and "connector" in graph and "in_intersection" in graph):
        return []
    bits = _nsgraph.EDGE_FLAGS
    connector = np.asarray(graph["connector"], dtype=bool)
    inside = np.asarray(graph["in_intersection"], dtype=bool)
    flags = connector.astype(np.uint8) * bits["connector"] | inside.astype(np.uint8) * bits["in_intersection"]
    if "change" in graph:
        names = _nsgraph.MAP_CHANGES
        change_bits = np.array([bits.get(name, 0) for name in names], dtype=np.uint8)
        codes = np.asarray(graph["change"], dtype=np.int64)
        if codes.size and (codes.min() < 0 or codes.max() >= len(names)):
            from .errors import DataError
            raise DataError(f"change: codes into MAP_CHANGES (0 … {len(names) - 1}) expected")
        flags = flags | change_bits[codes]
    return flags.astype(np.uint8).tolist()


def _tile_document(graph):
    nodes, edges = graph_arrays(graph)
    tile = {"nodes": nodes.tolist(), "edges": edges.tolist()}
    if isinstance(graph, dict):
        for name in ("node_scores", "edge_scores"):
            if name in graph:
                tile[name] = np.asarray(graph[name], dtype=np.float64).tolist()
    return tile


def submission_document(tiles):
    """A submission-format dict from {key: graph} (any form graph_arrays takes); a dict
    that already has ``tiles`` is returned as it is."""
    if isinstance(tiles, dict) and "tiles" in tiles:
        return tiles
    return {"schema_version": "1", "tiles": {str(k): _tile_document(g) for k, g in tiles.items()}}


def _source(value):
    """(text or path, is_path, label) for the C++ side."""
    if isinstance(value, (str, os.PathLike)):
        path = os.fspath(value)
        return path, True, path
    # repr-exact floats; NaN passes as "NaN" so the C++ parser names it
    return json.dumps(submission_document(value)), False, MEMORY_LABEL


def _params_json(params):
    return json.dumps(params)


def score(ground_truth, submission, split=None, threads=0, verify=True, max_seconds=3600, **params):
    """Scores a submission like ``nsgraph score`` and returns its JSON report as a dict.

    ground_truth: a dataset folder (its ``split``; default: the split the submission's keys
    are tiles of, as the CLI), a ground-truth file in
    the submission format, or in memory {key: graph} / a submission-format dict. Only a
    dataset folder carries the edge classes: otherwise the per-class recalls
    (``geo_recall_connector``, ...) are undefined.
    submission: a submission file, or in memory likewise. params: docs/metrics.md parameters
    (resolution_m, snap_m, ...). Raises SubmissionError (with .issues) when the submission
    has problems (the CLI's exit 1), nsgraph.errors.* for bad input (exit 2). A dataset
    folder is read through its manifest: the split's shards must be listed, present, of their
    recorded size and (verify=True, the CLI's default) sha256, with no unlisted shard beside
    them; the report's ``ground_truth_verification`` says which. ``max_seconds``: the
    wall-clock budget of scoring the tiles (``--max-seconds``; 0 = none), beyond which
    ConfigError is raised.
    """
    gt, gt_is_path, gt_label = _source(ground_truth)
    sub, sub_is_path, sub_label = _source(submission)
    report, issues, text = _nsgraph.score(gt, gt_is_path, sub, sub_is_path, split or "", _params_json(params),
                                          threads, SCHEMAS_DIR, gt_label, sub_label, bool(verify), float(max_seconds))
    if report is None:
        raise SubmissionError(f"{len(issues)} problem(s) in submission {sub_label}; not scored:\n{text}", issues)
    return report


def score_tile(gt, pred, key="tile", prior=None, **params):
    """Metrics of one tile (the report's per-tile entry: values and counts). gt, pred: any
    form graph_arrays takes; pred None = a missing prediction. A dataset tile's graph
    brings its edge classes (the per-class recalls); other forms have none. A map-update
    tile (``ds[i]``, whose ``prior_graph`` is taken unless ``prior`` is given) or a ``prior``
    graph brings the change metrics (docs/metrics.md "Map change"). The prediction gets a file's
    checks first (finite coordinates, node indices in range, the scoring limits): problems
    raise SubmissionError (with .issues), a ground truth with them DataError."""
    if prior is None and isinstance(gt, dict) and isinstance(gt.get("prior_graph"), dict):
        prior = gt["prior_graph"]
    gt_nodes, gt_edges = graph_arrays(gt)
    if pred is None:
        pred_nodes = pred_edges = None
    else:
        pred_nodes, pred_edges = graph_arrays(pred)
    prior_nodes = prior_edges = None
    if prior is not None:
        prior_nodes, prior_edges = graph_arrays(prior)
    values, issues, text = _nsgraph.score_tile(gt_nodes, gt_edges, edge_flags(gt), pred_nodes, pred_edges,
                                               _params_json(params), key, prior_nodes, prior_edges,
                                               edge_flags(prior) if prior is not None else [])
    if values is None:
        raise SubmissionError(f"{len(issues)} problem(s) in the prediction of tile {key}; not scored:\n{text}", issues)
    return values


def write_submission(path, tiles):
    """Writes {key: (nodes, edges)} (or any graph form) as a submission file (coordinates
    rounded to 1/1000 px, as ``nsgraph predict`` writes them) and checks it like ``nsgraph
    score``; raises SubmissionError (the file removed) on problems such as NaN coordinates."""
    keys = sorted(str(k) for k in tiles)
    by_key = {str(k): g for k, g in tiles.items()}
    arrays = [graph_arrays(by_key[k]) for k in keys]
    issues, text = _nsgraph.write_submission(os.fspath(path), keys, [a[0] for a in arrays],
                                             [a[1] for a in arrays], SCHEMAS_DIR)
    if issues:
        raise SubmissionError(f"{len(issues)} problem(s) in the submission for {os.fspath(path)}; not written:\n{text}",
                              issues)
    return os.fspath(path)


def check_submission(submission):
    """The problems ``nsgraph score`` would refuse a submission for (list of dicts; empty
    = valid). submission: a path or in-memory tiles."""
    source, is_path, label = _source(submission)
    issues, _ = _nsgraph.check_submission(source, is_path, label, SCHEMAS_DIR)
    return issues

"""LaneGraphNet's training labels from a tile's ground-truth graph, all through the paper's
adaptive ground truth (nsgraph.adaptive_ground_truth, §III-C) and lib/model's direction
bins:

- anchor heatmap: a Gaussian (σ = 1 cell) around every ground-truth node, 1 at the node's
  cell; offset: where in that cell the node lies (in cells, as net_anchors decodes it);
- direction: each cell centre projected onto its nearest lane segment (within 1 m); the
  class is that lane's 20° bin, background (18) elsewhere;
- has-connection: anchors (jittered ground-truth nodes, or the network's own anchors)
  projected onto their lanes, consecutive ones connected; candidate pairs within the pair
  radius are positive when the adaptive ground truth connects them.
"""
import numpy as np

from .. import _nsgraph
from ..groundtruth import adaptive_ground_truth
from .lanegraphnet import STRIDE

DIRECTION_RADIUS_PX = 5.0       # 1 m: a lane's direction is labelled this close to its centreline
LABEL_MAX_DISTANCE_PX = 10.0    # anchors farther from every lane are not projected (lib/model PairOptions)
LABEL_MAX_FOLLOW_PX = 100.0
BACKGROUND = 18


def cell_centres(size_px):
    cells = size_px // STRIDE
    c = np.arange(cells) * STRIDE + (STRIDE - 1) / 2.0
    u, v = np.meshgrid(c, c)
    return np.stack([u.ravel(), v.ravel()], 1)


def anchor_targets(nodes_px, size_px, sigma_cells=1.0):
    """heat (h, w) float32, offset (2, h, w) float32, mask (h, w) bool of the node cells."""
    cells = size_px // STRIDE
    heat = np.zeros((cells, cells), np.float32)
    offset = np.zeros((2, cells, cells), np.float32)
    mask = np.zeros((cells, cells), bool)
    if len(nodes_px) == 0:
        return heat, offset, mask
    pos = (np.asarray(nodes_px, np.float64) - (STRIDE - 1) / 2.0) / STRIDE   # continuous cell coordinates
    idx = np.floor((np.asarray(nodes_px, np.float64) + 0.5) / STRIDE).astype(int)
    inside = (idx >= 0).all(1) & (idx < cells).all(1)
    pos, idx = pos[inside], idx[inside]
    grid = np.arange(cells, dtype=np.float64)
    for (cu, cv), (iu, iv) in zip(pos, idx):
        g = np.exp(-((grid[None, :] - cu) ** 2 + (grid[:, None] - cv) ** 2) / (2 * sigma_cells ** 2))
        np.maximum(heat, g.astype(np.float32), out=heat)
    for (cu, cv), (iu, iv) in zip(pos, idx):
        heat[iv, iu] = 1.0
        offset[:, iv, iu] = (cu - iu, cv - iv)
        mask[iv, iu] = True
    return heat, offset, mask


def direction_targets(graph, size_px):
    """(h, w) int64 classes: the 20° bin of the nearest lane within 1 m, else background."""
    cells = size_px // STRIDE
    out = np.full(cells * cells, BACKGROUND, np.int64)
    if len(graph["edges"]) == 0:
        return out.reshape(cells, cells)
    gt = adaptive_ground_truth(graph, cell_centres(size_px), frame="px", max_distance=DIRECTION_RADIUS_PX,
                               max_follow=0.0)
    if len(gt["input"]):
        nodes = np.asarray(graph["nodes_px"], np.float64)
        e = np.asarray(graph["edges"])[gt["edge"]]
        out[gt["input"]] = _nsgraph.direction_bins(nodes[e[:, 1]] - nodes[e[:, 0]])
    return out.reshape(cells, cells)


def candidate_pairs(points, radius_px):
    """Unordered pairs (i < j) at most radius_px apart, sorted (lib/model candidate_pairs)."""
    p = np.asarray(points, np.float64).reshape(-1, 2)
    if len(p) < 2:
        return np.zeros((0, 2), np.int64)
    d = np.linalg.norm(p[:, None, :] - p[None, :, :], axis=2)
    i, j = np.nonzero(np.triu(d <= radius_px, 1))
    return np.stack([i, j], 1).astype(np.int64)


def connection_labels(graph, points, pairs):
    """1.0 where the adaptive ground truth connects a pair's anchors (either way), else 0."""
    if len(pairs) == 0:
        return np.zeros(0, np.float32)
    if len(graph["edges"]) == 0 or len(points) == 0:
        return np.zeros(len(pairs), np.float32)
    gt = adaptive_ground_truth(graph, points, frame="px", max_distance=LABEL_MAX_DISTANCE_PX,
                               max_follow=LABEL_MAX_FOLLOW_PX)
    inp = gt["input"]
    linked = {(int(inp[a]), int(inp[b])) for a, b in gt["edges"]}
    linked |= {(b, a) for a, b in linked}
    return np.array([(int(i), int(j)) in linked for i, j in pairs], np.float32)


def jittered_nodes(nodes_px, size_px, rng, drop=0.1, sigma_px=1.0):
    """Training anchors near the ground truth: each node inside the tile kept with
    1 − drop, moved by N(0, σ²) per axis, clipped into the tile."""
    n = np.asarray(nodes_px, np.float64).reshape(-1, 2)
    keep = (rng.random(len(n)) >= drop) & (n >= -0.5).all(1) & (n < size_px - 0.5).all(1)
    moved = n + rng.normal(0.0, sigma_px, n.shape)
    return np.clip(moved[keep], 0.0, size_px - 1.0)

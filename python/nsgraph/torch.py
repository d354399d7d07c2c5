"""PyTorch side of nsgraph: a map-style Dataset yielding tensors, a collate for
variable-size graphs, and the paper's augmentations (seeded). torch is imported here
only, so ``import nsgraph`` does not need it.

A sample::

    key                str
    lidar    uint8   (H, W)        rgb uint8 (3, H, W)   semantic uint8 (H, W)
    vehicle  float32 (H, W)        coverage uint8 (H, W)
    nodes    float32 (N, 2) u, v   nodes_m float64 (N, 2) x, y (where the pixel lies)
    edges    int64   (E, 2)        lane_tokens [E str]   meta dict
    junction int64   (N,)          turn int64 (E,)       connector, in_intersection bool (E,)
    lane_changes int64 (C, 2)      (the graph attributes: nsgraph.JUNCTIONS, nsgraph.TURNS)
"""
import numpy as np
import torch

from .dataset import LAYERS, MODALITIES, TURNS, Dataset

NO_DATA = {name: m["nodata"] for name, m in LAYERS.items() if m["nodata"] is not None}
COVERAGE_BIT = {name: m["coverage_bit"] for name, m in LAYERS.items() if m["coverage_bit"]}


class Augment:
    """The paper's augmentations, applied to numpy tiles before they become tensors.

    dropout: {modality: probability} — the whole input set to "no data" (and its coverage
    bit cleared). brightness, contrast: jitter amplitudes for RGB and LiDAR — a valid pixel
    x becomes (x − mean) · c + mean + b · 255, c ∈ [1 − contrast, 1 + contrast],
    b ∈ [−brightness, brightness], clipped to [1, 255] so it stays valid (0 = no data).
    flips, rot90: random horizontal / vertical flips and quarter turns, moving the graph's
    pixel coordinates and the vehicle headings with the rasters (edge directions kept).
    """

    def __init__(self, dropout=None, brightness=0.0, contrast=0.0, flips=False, rot90=False):
        self.dropout = dict(dropout or {})
        unknown = [m for m in self.dropout if m not in MODALITIES]
        if unknown:
            raise ValueError(f"dropout: unknown modalities {unknown}; expected some of {MODALITIES}")
        self.brightness = float(brightness)
        self.contrast = float(contrast)
        self.flips = bool(flips)
        self.rot90 = bool(rot90)

    def __call__(self, tile, rng):
        """Augments a tile dict (as nsgraph.Dataset returns it) in place; rng: a
        numpy Generator. The draws happen in a fixed order whatever the tile holds."""
        for m in MODALITIES:
            drop = rng.random() < self.dropout.get(m, 0.0)
            if drop and m in tile:
                tile[m] = np.full_like(tile[m], NO_DATA[m])
                if m in COVERAGE_BIT:
                    tile["coverage"] = tile["coverage"] & np.uint8(~COVERAGE_BIT[m] & 0xFF)
        for m in ("rgb", "lidar"):
            c = 1.0 + rng.uniform(-self.contrast, self.contrast)
            b = rng.uniform(-self.brightness, self.brightness) * 255.0
            if m in tile and (self.contrast > 0 or self.brightness > 0):
                tile[m] = _jitter(tile[m], c, b)
        flip_u = self.flips and rng.random() < 0.5
        flip_v = self.flips and rng.random() < 0.5
        turns = int(rng.integers(0, 4)) if self.rot90 else 0
        if flip_u:
            _transform(tile, "flip_u")
        if flip_v:
            _transform(tile, "flip_v")
        for _ in range(turns):
            _transform(tile, "rot90")
        return tile


def _jitter(image, contrast, brightness):
    valid = image.reshape(image.shape[0], image.shape[1], -1).any(axis=2)
    if not valid.any():
        return image
    x = image.astype(np.float32)
    mean = x[valid].mean()
    y = np.clip((x - mean) * contrast + mean + brightness, 1.0, 255.0)
    out = np.where(valid.reshape(valid.shape + (1,) * (image.ndim - 2)), np.rint(y), 0.0)
    return out.astype(np.uint8)


# Heading h = bearing clockwise from north / 2π. Mirroring east-west (u → W−1−u) maps a
# bearing θ to −θ; north-south (v → H−1−v) to π − θ; a counter-clockwise quarter turn of
# the image (np.rot90) turns north to west: θ − π/2.
_HEADING = {"flip_u": lambda h: (1.0 - h) % 1.0, "flip_v": lambda h: (0.5 - h) % 1.0,
            "rot90": lambda h: (h - 0.25) % 1.0}


def _transform(tile, op):
    for m in LAYERS:
        if m not in tile:
            continue
        a = tile[m]
        a = a[:, ::-1] if op == "flip_u" else a[::-1, :] if op == "flip_v" else np.rot90(a)
        tile[m] = np.ascontiguousarray(a)
    if "vehicle" in tile:
        v = tile["vehicle"]
        has = v >= 0
        v = v.copy()
        v[has] = _HEADING[op](v[has].astype(np.float64)).astype(np.float32)
        tile["vehicle"] = v
    graph = tile.get("graph")
    if graph is not None:
        size = tile["coverage"].shape  # (H, W) after the raster transform
        uv = graph["nodes_px"].copy()
        if op == "flip_u":
            uv[:, 0] = size[1] - 1 - uv[:, 0]
        elif op == "flip_v":
            uv[:, 1] = size[0] - 1 - uv[:, 1]
        else:  # np.rot90: new row = W−1−u, new column = v
            uv = np.stack([graph["nodes_px"][:, 1], size[0] - 1 - graph["nodes_px"][:, 0]], axis=1)
        graph["nodes_px"] = uv
        if op != "rot90" and "turn" in graph:  # a mirror image turns left into right
            turn = graph["turn"].copy()
            left, right = TURNS.index("left"), TURNS.index("right")
            turn[graph["turn"] == left] = right
            turn[graph["turn"] == right] = left
            graph["turn"] = turn


def _nodes_m(tile):
    """Map metres of the (possibly moved) pixel positions, from the tile's bounds."""
    meta = tile.get("meta")
    uv = tile["graph"]["nodes_px"]
    if not meta:
        return tile["graph"]["nodes_m"]
    x_west, _, _, y_north = meta["bounds_m"]
    res = meta["resolution_m"]
    return np.stack([x_west + (uv[:, 0] + 0.5) * res, y_north - (uv[:, 1] + 0.5) * res], axis=1)


class TorchDataset(torch.utils.data.Dataset):
    """nsgraph.Dataset as tensors, optionally augmented. Augmentation of tile i in epoch e
    draws from numpy's Generator seeded with (seed, e, i): the same whatever the worker
    count or order. Call set_epoch(e) each epoch (in the main process, before iterating)."""

    def __init__(self, root, split, modalities=MODALITIES, augment=None, seed=0):
        self.tiles = Dataset(root, split, modalities=modalities)
        self.augment = augment
        self.seed = int(seed)
        self.epoch = 0

    def set_epoch(self, epoch):
        self.epoch = int(epoch)

    def __len__(self):
        return len(self.tiles)

    def __getitem__(self, i):
        tile = self.tiles[i]
        if self.augment is not None:
            self.augment(tile, np.random.default_rng([self.seed, self.epoch, int(i)]))
        return to_tensors(tile)


def to_tensors(tile):
    sample = {"key": tile["key"]}
    for m, layer in LAYERS.items():
        if m in tile:  # bands first, like torchvision
            a = tile[m].transpose(2, 0, 1) if layer["bands"] > 1 else tile[m]
            sample[m] = torch.from_numpy(np.ascontiguousarray(a))
    if "graph" in tile:
        sample["nodes"] = torch.from_numpy(tile["graph"]["nodes_px"].astype(np.float32))
        sample["nodes_m"] = torch.from_numpy(np.asarray(_nodes_m(tile), dtype=np.float64))
        sample["edges"] = torch.from_numpy(tile["graph"]["edges"])
        sample["lane_tokens"] = list(tile["graph"]["lane_tokens"])
        for name in ("junction", "turn", "connector", "in_intersection", "lane_changes"):
            if name in tile["graph"]:
                sample[name] = torch.from_numpy(np.ascontiguousarray(tile["graph"][name]))
    if "meta" in tile:
        sample["meta"] = tile["meta"]
    return sample


def collate(samples):
    """Batches samples: rasters stacked (B, ...); graphs concatenated PyG-style — nodes
    (ΣN, 2), edges (ΣE, 2) with node indices offset into the concatenation, node_batch
    (ΣN,) the sample of each node, num_nodes / num_edges (B,); the graph attributes
    concatenated (junction (ΣN,), turn / connector / in_intersection (ΣE,)), lane_changes
    (ΣC, 2) offset like edges with num_lane_changes (B,); keys, lane_tokens and meta as lists."""
    batch = {"key": [s["key"] for s in samples]}
    for m in LAYERS:
        if m in samples[0]:
            batch[m] = torch.stack([s[m] for s in samples])
    if "nodes" in samples[0]:
        counts = [len(s["nodes"]) for s in samples]
        offsets = np.cumsum([0] + counts[:-1])
        batch["nodes"] = torch.cat([s["nodes"] for s in samples]).reshape(-1, 2)
        batch["nodes_m"] = torch.cat([s["nodes_m"] for s in samples]).reshape(-1, 2)
        batch["edges"] = torch.cat([s["edges"] + int(o) for s, o in zip(samples, offsets)]).reshape(-1, 2)
        batch["node_batch"] = torch.repeat_interleave(torch.arange(len(samples)), torch.tensor(counts))
        batch["num_nodes"] = torch.tensor(counts)
        batch["num_edges"] = torch.tensor([len(s["edges"]) for s in samples])
        batch["lane_tokens"] = [s["lane_tokens"] for s in samples]
        for name in ("junction", "turn", "connector", "in_intersection"):
            if name in samples[0]:
                batch[name] = torch.cat([s[name] for s in samples])
        if "lane_changes" in samples[0]:  # like edges: node indices into the concatenation
            batch["lane_changes"] = torch.cat(
                [s["lane_changes"] + int(o) for s, o in zip(samples, offsets)]).reshape(-1, 2)
            batch["num_lane_changes"] = torch.tensor([len(s["lane_changes"]) for s in samples])
    if "meta" in samples[0]:
        batch["meta"] = [s["meta"] for s in samples]
    return batch


def collate_frames(items):
    """Batches nsgraph.frames.Dataset items for a per-frame model. Cameras in the first
    item's channel order: ``K`` (B, C, 3, 3), ``extrinsic`` (B, C, 4, 4) camera → ego,
    ``images`` (B, C, 3, H, W) uint8 when the items hold images (all one size); ``pose``
    (B, 4, 4); centerlines padded to the batch's largest count, ``centerlines`` (B, N, P, 3)
    float32 with ``centerline_mask`` (B, N) bool (every centerline has the export's P
    points), ``topology`` (B, N, N) uint8 and ``is_connector`` (B, N); tokens, scenes and
    timestamps as lists."""
    channels = list(items[0]["cameras"])
    for it in items:
        if list(it["cameras"]) != channels:
            raise ValueError(f"frame {it['token']}: cameras {list(it['cameras'])}, expected {channels} as the batch's")
    b = len(items)
    n = max((len(it["centerlines"]) for it in items), default=0)
    p = next((len(c) for it in items for c in it["centerlines"]), 0)
    lanes = np.zeros((b, n, p, 3), np.float32)
    mask = np.zeros((b, n), bool)
    topology = np.zeros((b, n, n), np.uint8)
    connector = np.zeros((b, n), bool)
    for i, it in enumerate(items):
        k = len(it["centerlines"])
        if k:
            lanes[i, :k] = np.stack(it["centerlines"])
            topology[i, :k, :k] = it["topology"]
            connector[i, :k] = it["is_connector"]
        mask[i, :k] = True
    batch = {"token": [it["token"] for it in items], "scene": [it["scene"] for it in items],
             "timestamp": [it["timestamp"] for it in items], "cameras": channels,
             "K": torch.from_numpy(np.stack([[it["cameras"][c]["K"] for c in channels] for it in items])),
             "extrinsic": torch.from_numpy(np.stack([[it["cameras"][c]["extrinsic"] for c in channels] for it in items])),
             "pose": torch.from_numpy(np.stack([it["pose"] for it in items])),
             "centerlines": torch.from_numpy(lanes), "centerline_mask": torch.from_numpy(mask),
             "topology": torch.from_numpy(topology), "is_connector": torch.from_numpy(connector)}
    if "images" in items[0]:
        batch["images"] = torch.from_numpy(np.stack([[it["images"][c].transpose(2, 0, 1) for c in channels]
                                                     for it in items]))
    return batch

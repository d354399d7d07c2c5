"""Frames: the per-key-frame records of ``nsgraph frames`` (docs/frames.md) for per-frame
models, and their scorer. ``Dataset`` lists a split's records through the export's
manifest and reads each through the library's reader of the export's documents (the one
``nsgraph score --frames`` and ``predict --frames`` use: its size and type checked before it
is read, its sha256, every field), gives calibration as arrays and decodes camera images on
demand with the library's JPEG decoder; ``score_frames`` is ``nsgraph score --frames``
(DET_l, TOP_ll, lane_score)."""
import json
import os
import tempfile

import numpy as np

from . import _nsgraph
from .errors import DataError, SubmissionError

SPLITS = ("train", "val", "test")


def _transform(t):
    """A 4 x 4 float64 matrix from {"rotation": 3 x 3, "translation": 3}."""
    m = np.eye(4)
    m[:3, :3] = np.asarray(t["rotation"], dtype=np.float64)
    m[:3, 3] = np.asarray(t["translation"], dtype=np.float64)
    return m


class Dataset:
    """The records of one split of a frames export.

    ``ds[i]`` is a dict: ``token`` (sample token, the results key), ``scene``,
    ``timestamp`` (µs), ``split``, ``location``, ``pose`` (4 x 4 ego → global),
    ``cameras`` {channel: {``image_path`` (absolute), ``K`` (3 x 3), ``extrinsic`` (4 x 4
    camera → ego), ``ego_pose`` (4 x 4), ``width``, ``height``}}, ``centerlines`` (list of
    (P, 3) float32, ego frame, m), ``centerlines_2m`` (the ≤ 2 m nodes), ``is_connector``
    (bool array), ``topology`` ((N, N) uint8: [i, j] = 1 when j succeeds i) and, with
    ``images=True``, ``images`` {channel: (H, W, 3) uint8}. ``dataroot`` overrides the
    release folder of referenced images (the manifest's ``source.dataroot``).
    """

    def __init__(self, root, split="test", images=False, dataroot=None, image_scale=1, verify=True):
        self.root = os.fspath(root)
        # The manifest read and checked by the library (IoError, ParseError naming the file,
        # the JSON pointer and what was expected).
        self._export = _nsgraph.FramesExport(self.root)
        self.manifest = self._export.manifest
        if split not in SPLITS:
            raise DataError(f"{os.path.join(self.root, 'manifest.json')}: split '{split}': expected one of "
                            f"{', '.join(SPLITS)}")
        self.split = split
        self.images = images
        self.image_scale = image_scale
        self.verify = verify
        self.dataroot = os.fspath(dataroot) if dataroot else self._export.dataroot
        self._paths = self._export.records(split)

    def __len__(self):
        return len(self._paths)

    def keys(self):
        """The records' paths in the export, in order."""
        return list(self._paths)

    def record(self, i):
        """The record (dict, its own layout; points as (P, 3) float64 arrays, topology_lclc as
        an (N, N) uint8 array) after its size, sha256 and every field are checked."""
        return self._export.record(self._paths[i], bool(self.verify))

    def image(self, camera):
        """(H, W, 3) uint8 of one camera entry of ``ds[i]["cameras"]``."""
        return _nsgraph.decode_jpeg(camera["image_path"], int(self.image_scale))

    def __getitem__(self, i):
        if not -len(self) <= i < len(self):
            raise IndexError(i)
        r = self.record(i % len(self))
        image_root = self.root if self._export.copy_images else self.dataroot
        cameras = {}
        for channel, c in r["sensor"].items():
            cameras[channel] = {"image_path": os.path.join(image_root, c["image_path"]),
                                "K": np.asarray(c["intrinsic"]["K"], dtype=np.float64),
                                "extrinsic": _transform(c["extrinsic"]), "ego_pose": _transform(c["ego_pose"]),
                                "width": c["width"], "height": c["height"]}
        lanes = r["annotation"]["lane_centerline"]
        item = {"token": r["sample_token"], "scene": r["segment_id"], "timestamp": r["timestamp"], "split": r["split"],
                "location": r["meta_data"]["location"], "pose": _transform(r["pose"]), "cameras": cameras,
                "centerlines": [c["points"].astype(np.float32) for c in lanes],
                "centerlines_2m": [c["points_2m"].astype(np.float32) for c in lanes],
                "is_connector": np.asarray([c["is_intersection_or_connector"] for c in lanes], dtype=bool),
                "topology": r["annotation"]["topology_lclc"]}
        if self.images:
            item["images"] = {ch: self.image(c) for ch, c in cameras.items()}
        return item


def score_frames(ground_truth, results, split="test", verify=True, max_file_mb=None, graph_metrics=False,
                 max_seconds=3600):
    """``nsgraph score --frames``: the report (dict) of an OpenLane-V2 results document
    (a path, or the dict itself) against a frames export (its ``split``) or a ground-truth
    document file; ``graph_metrics`` = ``--graph-metrics``; ``max_seconds`` = ``--max-seconds``
    (the scoring's wall-clock budget, 0 = none; ConfigError beyond it). Raises SubmissionError
    (with .issues) when the results have problems (the CLI's exit 1), nsgraph.errors.* for a
    bad ground truth (exit 2)."""
    max_bytes = int(max_file_mb * 1024 * 1024) if max_file_mb else 0
    if isinstance(results, (str, os.PathLike)):
        return _score(os.fspath(ground_truth), os.fspath(results), split, verify, max_bytes, graph_metrics,
                      max_seconds)
    with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
        json.dump(results, f)
    try:
        return _score(os.fspath(ground_truth), f.name, split, verify, max_bytes, graph_metrics, max_seconds)
    finally:
        os.unlink(f.name)


def _score(ground_truth, results, split, verify, max_bytes, graph_metrics, max_seconds):
    report, issues, text = _nsgraph.score_frames(ground_truth, results, split, verify, max_bytes, graph_metrics,
                                                 float(max_seconds))
    if report is None:
        raise SubmissionError(f"{len(issues)} problem(s) in results {results}; not scored:\n{text}", issues)
    return json.loads(report)

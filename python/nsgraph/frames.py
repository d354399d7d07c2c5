"""Frames: the per-key-frame records of ``nsgraph frames`` (docs/frames.md) for per-frame
models, and their scorer. ``Dataset`` lists a split's records through the export's
manifest (each record's size and sha256 checked when it is read), gives calibration as
arrays and decodes camera images on demand with the library's JPEG decoder;
``score_frames`` is ``nsgraph score --frames`` (DET_l, TOP_ll, lane_score)."""
import hashlib
import json
import os
import tempfile

import numpy as np

from . import _nsgraph
from .errors import DataError, IoError, ParseError, SubmissionError

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
        manifest_path = os.path.join(self.root, "manifest.json")
        try:
            with open(manifest_path) as f:
                self.manifest = json.load(f)
        except OSError as e:
            raise IoError(f"{manifest_path}: cannot read ({e.strerror}); expected an nsgraph frames export") from None
        except ValueError as e:
            raise ParseError(f"{manifest_path}: not JSON ({e})") from None
        if self.manifest.get("kind") != "nsgraph-frames":
            raise ParseError(f"{manifest_path}:/kind: expected \"nsgraph-frames\" (the manifest of `nsgraph frames`)")
        if split not in SPLITS:
            raise DataError(f"{manifest_path}: split '{split}': expected one of {', '.join(SPLITS)}")
        self.split = split
        self.images = images
        self.image_scale = image_scale
        self.verify = verify
        self.dataroot = os.fspath(dataroot) if dataroot else self.manifest["source"]["dataroot"]
        self._files = [f for f in self.manifest["files"]
                       if f["path"].startswith(split + "/") and "/info/" in f["path"]]

    def __len__(self):
        return len(self._files)

    def keys(self):
        """The records' paths in the export, in order."""
        return [f["path"] for f in self._files]

    def record(self, i):
        """The raw record (dict) as written, after its size and sha256 are checked."""
        entry = self._files[i]
        path = os.path.join(self.root, entry["path"])
        try:
            with open(path, "rb") as f:
                data = f.read()
        except OSError as e:
            raise IoError(f"{path}: cannot read ({e.strerror}); the manifest lists it") from None
        if len(data) != entry["bytes"] or (self.verify and hashlib.sha256(data).hexdigest() != entry["sha256"]):
            raise DataError(f"{path}: expected the size and sha256 {os.path.join(self.root, 'manifest.json')} records")
        return json.loads(data)

    def image(self, camera):
        """(H, W, 3) uint8 of one camera entry of ``ds[i]["cameras"]``."""
        return _nsgraph.decode_jpeg(camera["image_path"], int(self.image_scale))

    def __getitem__(self, i):
        if not -len(self) <= i < len(self):
            raise IndexError(i)
        r = self.record(i % len(self))
        image_root = self.root if self.manifest["config"].get("copy_images") else self.dataroot
        cameras = {}
        for channel, c in r["sensor"].items():
            cameras[channel] = {"image_path": os.path.join(image_root, c["image_path"]),
                                "K": np.asarray(c["intrinsic"]["K"], dtype=np.float64),
                                "extrinsic": _transform(c["extrinsic"]), "ego_pose": _transform(c["ego_pose"]),
                                "width": c["width"], "height": c["height"]}
        lanes = r["annotation"]["lane_centerline"]
        n = len(lanes)
        item = {"token": r["sample_token"], "scene": r["segment_id"], "timestamp": r["timestamp"], "split": r["split"],
                "location": r["meta_data"]["location"], "pose": _transform(r["pose"]), "cameras": cameras,
                "centerlines": [np.asarray(c["points"], dtype=np.float32) for c in lanes],
                "centerlines_2m": [np.asarray(c["points_2m"], dtype=np.float32) for c in lanes],
                "is_connector": np.asarray([c["is_intersection_or_connector"] for c in lanes], dtype=bool),
                "topology": np.asarray(r["annotation"]["topology_lclc"], dtype=np.uint8).reshape(n, n)}
        if self.images:
            item["images"] = {ch: self.image(c) for ch, c in cameras.items()}
        return item


def score_frames(ground_truth, results, split="test", verify=True, max_file_mb=None, graph_metrics=False):
    """``nsgraph score --frames``: the report (dict) of an OpenLane-V2 results document
    (a path, or the dict itself) against a frames export (its ``split``) or a ground-truth
    document file; ``graph_metrics`` = ``--graph-metrics``. Raises SubmissionError (with .issues) when the results have problems
    (the CLI's exit 1), nsgraph.errors.* for a bad ground truth (exit 2)."""
    max_bytes = int(max_file_mb * 1024 * 1024) if max_file_mb else 0
    if isinstance(results, (str, os.PathLike)):
        return _score(os.fspath(ground_truth), os.fspath(results), split, verify, max_bytes, graph_metrics)
    with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
        json.dump(results, f)
    try:
        return _score(os.fspath(ground_truth), f.name, split, verify, max_bytes, graph_metrics)
    finally:
        os.unlink(f.name)


def _score(ground_truth, results, split, verify, max_bytes, graph_metrics):
    report, issues, text = _nsgraph.score_frames(ground_truth, results, split, verify, max_bytes, graph_metrics)
    if report is None:
        raise SubmissionError(f"{len(issues)} problem(s) in results {results}; not scored:\n{text}", issues)
    return json.loads(report)

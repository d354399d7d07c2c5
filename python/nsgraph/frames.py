"""Frames: the per-key-frame records of ``nsgraph frames`` (docs/frames.md) for per-frame
models, and their scorer. ``Dataset`` lists a split's records through the export's
manifest and reads each through the library's reader of the export's documents (the one
``nsgraph score --frames`` and ``predict --frames`` use: its size and type checked before it
is read, its sha256, every field), gives calibration as arrays and decodes camera images on
demand with the library's JPEG decoder; ``score_frames`` is ``nsgraph score --frames``
(DET_l, TOP_ll, lane_score) and takes OpenLane-V2's results dicts as they are
(``from_openlanev2``, ``to_results_json``)."""
import json
import math
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
    """``nsgraph score --frames``: the report (dict) of results against a frames export (its
    ``split``) or a ground-truth document file. ``results`` is a path to a JSON results file,
    or a results dict as OpenLane-V2's ``format_results`` returns it — keys sample tokens or
    identifiers ``(split, segment_id, timestamp)``, points and ``topology_lclc`` as lists or
    numpy arrays (float32 or float64), taken unchanged (``from_openlanev2``).
    ``graph_metrics`` = ``--graph-metrics``; ``max_seconds`` = ``--max-seconds`` (the
    scoring's wall-clock budget, 0 = none; ConfigError beyond it). Raises SubmissionError
    (with .issues) when the results have problems (the CLI's exit 1), nsgraph.errors.* for a
    bad ground truth (exit 2)."""
    max_bytes = int(max_file_mb * 1024 * 1024) if max_file_mb else 0
    if isinstance(results, (str, os.PathLike)):
        return _score(os.fspath(ground_truth), os.fspath(results), split, verify, max_bytes, graph_metrics,
                      max_seconds)
    with tempfile.TemporaryDirectory(prefix="nsgraph-results-") as folder:
        path = os.path.join(folder, "results.json")
        to_results_json(results, path)
        return _score(os.fspath(ground_truth), path, split, verify, max_bytes, graph_metrics, max_seconds)


# OpenLane-V2's results nest 7 deep (results / key / predictions / lane_centerline / lane /
# points / point); a dict nested deeper is not a results dict and is refused, not recursed.
_MAX_RESULTS_DEPTH = 16


def _problem(at, expected, check="frames.results.schema"):
    """The SubmissionError the CLI's reader would report (its check names, docs/metrics.md)."""
    return SubmissionError(f"results{at}: expected {expected}",
                           [{"severity": "error", "check": check, "subject": f"results{at}",
                             "message": f"expected {expected}"}])


def _finite(ok, at):
    if not ok:
        raise _problem(at, "finite numbers (JSON holds no NaN or infinity)", "frames.results.finite")


def _results_key(key):
    """A results key as nsgraph's reader takes it: a sample token as it is, OpenLane-V2's
    identifier (split, segment_id, timestamp) as "split/segment_id/timestamp"."""
    if isinstance(key, str):
        return key
    if isinstance(key, tuple) and len(key) == 3:
        parts = [str(p.item() if isinstance(p, np.generic) else p) for p in key]
        if all(parts) and not any("/" in p for p in parts):
            return "/".join(parts)
    raise _problem(f"[{key!r}]", "a sample token or an identifier (split, segment_id, timestamp) "
                   "of names without '/'")


def _plain(value, at, depth):
    """A JSON-ready copy: numpy arrays and scalars as lists and numbers. float32 values widen
    to float64 exactly, so the file holds the submission's own numbers."""
    if depth > _MAX_RESULTS_DEPTH:
        raise _problem(at, f"a results dict nested at most {_MAX_RESULTS_DEPTH} deep")
    if isinstance(value, np.ndarray):
        if value.dtype.kind not in "biuf":
            raise _problem(at, f"a numeric array (not dtype {value.dtype})")
        _finite(value.dtype.kind != "f" or bool(np.isfinite(value).all()), at)
        return value.tolist()
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float):
        _finite(math.isfinite(value), at)
    if isinstance(value, dict):
        return {(k if isinstance(k, str) else str(k)): _plain(v, f"{at}/{k}", depth + 1) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v, f"{at}/{i}", depth + 1) for i, v in enumerate(value)]
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    raise _problem(at, f"lists, numbers, strings or numpy arrays (not {type(value).__name__})")


# What the scorer reads of a frame's predictions (docs/metrics.md "Frames", rule 1); the rest
# of an OpenLane-V2 dict — traffic elements, and the keys its evaluator adds to the dict it
# scored (`lane_centerline_1.0_idx_match_gt`, NaN-filled arrays) — is left out.
_LANE_KEYS = ("id", "points", "confidence")
# The lane-segment track's (OpenLane-V2 v2.1): lane segments and areas.
_SEGMENT_KEYS = ("id", "centerline", "left_laneline", "right_laneline", "confidence")
_AREA_KEYS = ("id", "category", "points", "confidence")


def _items(predictions, name, keys, at):
    items = predictions[name]
    if not isinstance(items, (list, tuple)):
        raise _problem(f"{at}/predictions/{name}", f"a list of {name}")
    out = []
    for i, item in enumerate(items):
        iat = f"{at}/predictions/{name}/{i}"
        if not isinstance(item, dict):
            raise _problem(iat, "{" + ", ".join(f'"{k}"' for k in keys) + "}")
        out.append({k: _plain(item[k], f"{iat}/{k}", 5) for k in keys if k in item})
    return out


def _frame(frame, at):
    if not isinstance(frame, dict) or not isinstance(frame.get("predictions"), dict):
        raise _problem(at, 'a frame {"predictions": {"lane_centerline": [...], "topology_lclc": n x n}}')
    predictions = frame["predictions"]
    out = {}
    for name, keys in (("lane_centerline", _LANE_KEYS), ("lane_segment", _SEGMENT_KEYS), ("area", _AREA_KEYS)):
        if name in predictions:
            out[name] = _items(predictions, name, keys, at)
    for name in ("topology_lclc", "topology_lsls"):
        if name in predictions:
            out[name] = _plain(predictions[name], f"{at}/predictions/{name}", 4)
    return {"predictions": out}


def from_openlanev2(results):
    """nsgraph's JSON results document (a dict of plain lists and numbers) from an OpenLane-V2
    results dict as its ``format_results`` returns it (what its evaluator unpickles):
    ``{"results": {(split, segment_id, timestamp): {"predictions": {"lane_centerline":
    [{"id", "points": (P, 3) array, "confidence"}], "topology_lclc": (n, n) array, …}}}, …}``.
    Identifier keys become "split/segment_id/timestamp" (``nsgraph score --frames`` finds the
    frame by it, as by its sample token); arrays become lists, float32 exactly. Only what the
    scorer reads is kept (centerlines and their topology; v2.1's lane segments, areas and
    topology_lsls; the submission's ``method`` name):
    traffic elements, and the keys OpenLane-V2's evaluator adds to a dict it has scored, are
    left out. Nothing is unpickled here: pass the dict, not a pickle file (a pickle is code;
    docs/hosting.md)."""
    if not isinstance(results, dict) or not isinstance(results.get("results"), dict):
        raise _problem("", 'a dict with "results": {identifier or sample token: {"predictions": ...}}')
    out = {"method": results["method"]} if isinstance(results.get("method"), str) else {}
    frames = {}
    for key, frame in results["results"].items():
        name = _results_key(key)
        if name in frames:
            raise _problem(f"[{key!r}]", f"one prediction per frame ({name!r} is named twice)")
        frames[name] = _frame(frame, f"/results/{name}")
    out["results"] = frames
    return out


def to_results_json(results, path):
    """Writes ``results`` (an OpenLane-V2 results dict, or nsgraph's JSON document) as the JSON
    results file ``nsgraph score --frames --submission`` reads; written to a temporary name
    beside ``path`` and renamed, so ``path`` is never half-written. Returns ``path``."""
    doc = from_openlanev2(results)
    path = os.fspath(path)
    folder = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=".results-", suffix=".json.tmp", dir=folder)
    try:
        with os.fdopen(fd, "w") as f:
            json.dump(doc, f, allow_nan=False)
            f.write("\n")
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    return path


def render(export, frame, out, split="test", submission=None, overwrite=False, bev_px_per_m=10.0):
    """``nsgraph frames render``: the frame (sample token or "split/segment_id/timestamp") of
    ``split`` drawn into each of its camera images (``<out>/<CHANNEL>.jpg``) and from above
    (``bev.png``), a results file's centerlines (``submission``, a path) beside the ground
    truth's. Returns {"files": [...], "truth_pieces_in_image": {channel: n}}; errors as the
    CLI names them (nsgraph.errors.*)."""
    files, pieces = _nsgraph.render_frame(os.fspath(export), frame, os.fspath(out), split,
                                          os.fspath(submission) if submission else "", overwrite,
                                          float(bev_px_per_m))
    return {"files": list(files), "truth_pieces_in_image": dict(pieces)}


def _score(ground_truth, results, split, verify, max_bytes, graph_metrics, max_seconds):
    report, issues, text = _nsgraph.score_frames(ground_truth, results, split, verify, max_bytes, graph_metrics,
                                                 float(max_seconds))
    if report is None:
        raise SubmissionError(f"{len(issues)} problem(s) in results {results}; not scored:\n{text}", issues)
    return json.loads(report)

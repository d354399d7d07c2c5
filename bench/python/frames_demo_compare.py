"""`nsgraph.score_frames` against OpenLane-V2's own evaluators on a whole frames export (the
`make demo` world's test split, 1 025 frames), with a TopoNet/LaneSegNet-style results dict:
OpenLane-V2 identifier tuples as keys, float32 numpy arrays, and ties everywhere — every
confidence 0.9, link probabilities from {1.0, 0.8}, conflicting duplicates — drawn as the
golden makers draw them (tests/data/golden/frames*/make_golden.py, `ties`). Prints DET_l,
TOP_ll (centerline evaluator) and DET_ls, DET_a, TOP_lsls, score (lane-segment evaluator) of
both and exits 1 when any differs by more than 1e-6.

OpenLane-V2 is needed (a checkout, python3-scipy, python3-shapely, python3-tqdm; the stubs of
the golden makers). The export must be record version 2 (`nsgraph frames`).

usage: frames_demo_compare.py --export FRAMES --openlanev2 CHECKOUT --python-package build/python
       [--split test] [--seed 5] [--out OUT.json]
"""
import argparse
import importlib
import importlib.util
import json
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
GOLDEN = os.path.join(HERE, "..", "..", "tests", "data", "golden")


def load(name, path):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def split_records(export, split):
    """(identifier, sample token) of every record of `split`, in the manifest's order."""
    manifest = json.load(open(os.path.join(export, "manifest.json")))
    out = []
    for f in manifest["files"]:
        path = f["path"]
        if path.startswith(split + "/") and "/info/" in path:
            parts = path.split("/")
            record = json.load(open(os.path.join(export, path)))
            out.append(((parts[0], parts[1], parts[3][:-len(".json")]), record["sample_token"]))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--export", required=True)
    ap.add_argument("--openlanev2", required=True)
    ap.add_argument("--python-package", required=True)
    ap.add_argument("--split", default="test")
    ap.add_argument("--seed", type=int, default=5)
    ap.add_argument("--out")
    a = ap.parse_args()
    lanes_golden = load("make_golden_lanes", os.path.join(GOLDEN, "frames", "make_golden.py"))
    segs_golden = load("make_golden_ls", os.path.join(GOLDEN, "frames-ls", "make_golden.py"))
    ev_lanes = lanes_golden.import_evaluator(a.openlanev2)
    ev_ls = importlib.import_module("openlanev2.lanesegment.evaluation.evaluate")
    dist_ls = importlib.import_module("openlanev2.lanesegment.evaluation.distance")
    fix = importlib.import_module("openlanev2.lanesegment.preprocessing.collect")._fix_pts_interpolate
    sys.path.insert(0, a.python_package)
    import nsgraph

    records = split_records(a.export, a.split)
    # The export's order (its manifest's, which is its data_dict's: what collect() keeps):
    # with tied confidences, the order of the frames is part of the result.
    all_lanes, all_segs = lanes_golden.read_exports([a.export]), segs_golden.read_exports([a.export])
    gt_lanes = {token: all_lanes[token] for _, token in records}
    gt_segs = {token: all_segs[token] for _, token in records}
    lanes = lanes_golden.ties(gt_lanes, a.seed, "all")
    segs = segs_golden.ties(gt_segs, a.seed * 7 + 1)
    # One TopoNet/LaneSegNet-style dict: identifier tuples, float32 arrays, both tracks.
    results = {}
    for ident, token in records:
        p, q = lanes[token]["predictions"], segs[token]["predictions"]
        f32 = lambda x: np.asarray(x, dtype=np.float32)  # noqa: E731
        results[ident] = {"predictions": {
            "lane_centerline": [dict(l, points=f32(l["points"]), confidence=np.float32(l["confidence"]))
                                for l in p["lane_centerline"]],
            "topology_lclc": np.asarray(p["topology_lclc"], dtype=np.float64).reshape(len(p["lane_centerline"]), -1),
            "lane_segment": [dict(s, **{n: f32(s[n]) for n in ("centerline", "left_laneline", "right_laneline")},
                                  confidence=np.float32(s["confidence"])) for s in q["lane_segment"]],
            "area": [dict(x, points=f32(x["points"]), confidence=np.float32(x["confidence"])) for x in q["area"]],
            "topology_lsls": np.asarray(q["topology_lsls"], dtype=np.float64).reshape(len(q["lane_segment"]), -1),
            "traffic_element": [], "topology_lcte": np.zeros((len(p["lane_centerline"]), 0))}}
    t0 = time.perf_counter()
    ours = nsgraph.score_frames(a.export, {"method": "ties", "results": results}, split=a.split)
    ours_s = time.perf_counter() - t0
    # The evaluators, on what the dict holds (float32 widened, as their pickles would give it).
    plain = lambda x: np.asarray(x, dtype=np.float64).tolist()  # noqa: E731
    lanes_plain = {t: {"predictions": {**lanes[t]["predictions"], "lane_centerline": [
        dict(l, points=plain(np.float32(l["points"])), confidence=float(np.float32(l["confidence"])))
        for l in lanes[t]["predictions"]["lane_centerline"]]}} for t in gt_lanes}
    segs_plain = {t: {"predictions": {**segs[t]["predictions"], "lane_segment": [
        dict(s, **{n: plain(np.float32(s[n])) for n in ("centerline", "left_laneline", "right_laneline")},
             confidence=float(np.float32(s["confidence"]))) for s in segs[t]["predictions"]["lane_segment"]],
        "area": [dict(x, points=plain(np.float32(x["points"])), confidence=float(np.float32(x["confidence"])))
                 for x in segs[t]["predictions"]["area"]]}} for t in gt_segs}
    t0 = time.perf_counter()
    theirs_lanes = lanes_golden.evaluate(ev_lanes, gt_lanes, lanes_plain)
    theirs_ls = segs_golden.evaluate(ev_ls, dist_ls, segs_golden.evaluator_gt(gt_segs, fix), segs_plain)
    theirs_s = time.perf_counter() - t0
    pairs = {"DET_l": (ours["DET_l"], theirs_lanes["DET_l"]), "TOP_ll": (ours["TOP_ll"], theirs_lanes["TOP_ll"])}
    for m in ("DET_ls", "DET_a", "TOP_lsls", "score"):
        pairs[m] = (ours["lane_segments"][m], theirs_ls[m])
    report = {"frames": len(records), "nsgraph_s": ours_s, "openlanev2_s": theirs_s,
              "metrics": {m: {"nsgraph": o, "openlanev2": t, "diff": abs(o - t)} for m, (o, t) in pairs.items()}}
    report["agree"] = all(v["diff"] <= 1e-6 for v in report["metrics"].values())
    print(json.dumps(report, indent=1))
    if a.out:
        json.dump(report, open(a.out, "w"), indent=1)
    sys.exit(0 if report["agree"] else 1)


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""Golden DET_ls / DET_a / TOP_lsls / score of the frames lane-segment metrics, from OpenLane-V2's
own v2.1 lane-segment evaluator.

Made once, committed beside this script, read by tests/unit/metrics/test_frames.cpp.
The numbers are computed by the evaluator's code, run from its source tree:

  OpenDriveLab/OpenLane-V2  f085b3d (Apache-2.0), openlanev2/lanesegment/evaluation/evaluate.py,
  its ground truth prepared by openlanev2/lanesegment/preprocessing/collect.py's
  _fix_pts_interpolate with data/OpenLane-V2/preprocess-ls.py's point counts
  (centerline and lanelines 10, area 20)

  /usr/bin/python3 make_golden.py --openlanev2 <OpenLane-V2 checkout> \
      --frames <frames export A> --frames <frames export B> [--seed 53]
  /usr/bin/python3 make_golden.py --openlanev2 <OpenLane-V2 checkout> --gt-json gt.json

(the second form reads the committed ground truth instead of the exports and remakes every
file byte for byte).

Debian 12 packages used: python3-numpy, python3-scipy, python3-shapely, python3-tqdm. Not
packaged in Debian and stubbed as ../frames/make_golden.py does: `similaritymeasures` (its
discrete Frechet supplied as that dynamic programme), `iso3166`, `cv2`, `ortools`.

Ground truth (gt.json): the `annotation` of every record of the exports given, as the records
hold it (lane segments' lines at 10 points, areas at the map's nodes): the evaluator gets
them through _fix_pts_interpolate, nsgraph through its own reading of the same lines. The
exports used for the committed files: `nsgraph frames --overlap keep` (record version 2) on
the e2e test release and dataset (tests/data/synth/e2e.json, tests/data/generate/e2e.json),
window default (A) and x +-30 m, y +-15 m (B): 50 frames.

Predictions (OpenLane-V2 results in JSON, lane segments and areas only, as LaneSegNet writes
them), perturbed copies by frame (seeded):
  pred.json        exact copies; lane segments and areas moved by 0.2-2.9 m; dropped; extra;
                   links flipped; lines resampled to 5 or 20 points; confidences distinct.
  pred-ties.json   every lane segment and area predicted (a tenth dropped), moved 0-2.5 m, in
                   three of ten a second prediction near the same ground truth; every
                   confidence 0.9 (ranked as the evaluator's numpy argsort ranks ties).
  pred-copy.json   the ground truth itself (as collect() resamples it), distinct confidences.

expected.json: per predictions file {"DET_ls", "DET_ls_per_threshold", "DET_a",
"DET_a_per_category", "TOP_lsls", "score", "frames"}, run under Debian 12's numpy 1.24.2.
"""
import argparse
import importlib
import json
import os
import random
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "frames"))
from make_golden import import_evaluator  # noqa: E402  (the stubs of the centerline golden)


def read_exports(dirs):
    gt = {}
    for k, d in enumerate(dirs):
        manifest = json.load(open(os.path.join(d, "manifest.json")))
        for f in manifest["files"]:
            if "/info/" not in f["path"]:
                continue
            record = json.load(open(os.path.join(d, f["path"])))
            a = record["annotation"]
            key = record["sample_token"] + ("" if k == 0 else "~" + "AB"[k])
            gt[key] = {
                "lane_centerline": [{"points": c["points"]} for c in a["lane_centerline"]],
                "topology_lclc": a["topology_lclc"],
                "lane_segment": [{n: s[n] for n in ("centerline", "left_laneline", "right_laneline")}
                                 for s in a["lane_segment"]],
                "area": [{"category": x["category"], "points": x["points"]} for x in a["area"]],
                "topology_lsls": a["topology_lsls"]}
    return dict(sorted(gt.items()))


def moved(points, d, a):
    return [[round(p[0] + d * np.cos(a), 4), round(p[1] + d * np.sin(a), 4), p[2]] for p in points]


def resample(points, n):
    pts = np.asarray(points, dtype=np.float64)
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))])
    t = np.linspace(0.0, s[-1], n)
    return np.round(np.stack([np.interp(t, s, pts[:, i]) for i in range(3)], axis=1), 4).tolist()


LINES = ("centerline", "left_laneline", "right_laneline")


def perturb(gt, seed):
    rnd = random.Random(seed)
    results = {}
    kinds = ["copy", "shift", "drop", "extra", "topology", "points", "mixed"]
    for f, (key, frame) in enumerate(gt.items()):
        kind = kinds[f % len(kinds)]
        segs, keep = [], []
        for i, s in enumerate(frame["lane_segment"]):
            if kind in ("drop", "mixed") and rnd.random() < 0.3:
                continue
            seg = {n: [list(p) for p in s[n]] for n in LINES}
            if kind in ("shift", "mixed") and rnd.random() < 0.8:
                d, a = rnd.uniform(0.2, 2.9), rnd.uniform(0, 2 * np.pi)
                seg = {n: moved(seg[n], d, a) for n in LINES}
            if kind == "points":
                m = rnd.choice([5, 20])
                seg = {n: resample(seg[n], m) for n in LINES}
            segs.append(seg)
            keep.append(i)
        n_true = len(segs)
        if kind in ("extra", "mixed"):
            for _ in range(rnd.randint(1, 4)):
                x0, y0, h = rnd.uniform(-45, 40), rnd.uniform(-22, 22), rnd.uniform(0, 2 * np.pi)
                c = [[x0 + k * np.cos(h), y0 + k * np.sin(h), 0.0] for k in range(10)]
                segs.append({"centerline": moved(c, 0, 0), "left_laneline": moved(c, 1.75, h + np.pi / 2),
                             "right_laneline": moved(c, 1.75, h - np.pi / 2)})
        n = len(segs)
        topo = [[0.0] * n for _ in range(n)]
        used = set()

        def prob(lo, hi):
            while True:
                v = round(rnd.uniform(lo, hi), 6)
                if v not in used and v != 0.5:
                    used.add(v)
                    return v
        for a in range(n):
            for b in range(n):
                linked = a < n_true and b < n_true and frame["topology_lsls"][keep[a]][keep[b]] == 1
                if kind in ("topology", "mixed") and rnd.random() < 0.3:
                    linked = not linked
                topo[a][b] = prob(0.51, 0.99) if linked else (prob(0.0, 0.49) if rnd.random() < 0.2 else 0.0)
        areas = []
        for x in frame["area"]:
            if kind in ("drop", "mixed") and rnd.random() < 0.3:
                continue
            pts = [list(p) for p in x["points"]]
            if kind in ("shift", "mixed") and rnd.random() < 0.8:
                pts = moved(pts, rnd.uniform(0.2, 1.8), rnd.uniform(0, 2 * np.pi))
            if kind == "points":
                pts = resample(pts, rnd.choice([4, 30]))
            areas.append({"category": x["category"], "points": pts})
        if kind in ("extra", "mixed"):
            for _ in range(rnd.randint(1, 3)):
                x0, y0 = rnd.uniform(-45, 40), rnd.uniform(-22, 22)
                areas.append({"category": rnd.choice([1, 2]),
                              "points": [[x0, y0, 0.0], [x0 + 4, y0, 0.0], [x0 + 4, y0 + 3, 0.0], [x0, y0, 0.0]]})
        results[key] = prediction(segs, topo, areas)
    all_items = [x for r in results.values() for x in r["predictions"]["lane_segment"] + r["predictions"]["area"]]
    for x, c in zip(all_items, rnd.sample(range(1, 10 ** 6), len(all_items))):
        x["confidence"] = c / 10 ** 6
    return results


def ties(gt, seed):
    rnd = random.Random(seed)
    results = {}
    for key, frame in gt.items():
        segs, source = [], []
        for i, s in enumerate(frame["lane_segment"]):
            if rnd.random() < 0.1:
                continue
            for _ in range(2 if rnd.random() < 0.3 else 1):
                d, a = rnd.uniform(0.0, 2.5), rnd.uniform(0, 2 * np.pi)
                segs.append({n: moved(s[n], d, a) for n in LINES})
                source.append(i)
        n = len(segs)
        topo = [[(rnd.choice([1.0, 0.8]) if frame["topology_lsls"][source[a]][source[b]] == 1 else 0.0)
                 for b in range(n)] for a in range(n)]
        areas = []
        for x in frame["area"]:
            if rnd.random() < 0.1:
                continue
            for _ in range(2 if rnd.random() < 0.3 else 1):
                areas.append({"category": x["category"],
                              "points": moved(x["points"], rnd.uniform(0.0, 1.4), rnd.uniform(0, 2 * np.pi))})
        results[key] = prediction(segs, topo, areas)
        for x in results[key]["predictions"]["lane_segment"] + results[key]["predictions"]["area"]:
            x["confidence"] = 0.9
    return results


def copy_of(ev_gt, seed):
    """The ground truth as the evaluator holds it (resampled), links 1 and others 0."""
    rnd = random.Random(seed)
    results = {}
    for key, frame in ev_gt.items():
        a = frame["annotation"]
        segs = [{n: np.asarray(s[n], dtype=np.float64).tolist() for n in LINES} for s in a["lane_segment"]]
        areas = [{"category": int(x["category"]), "points": np.asarray(x["points"], dtype=np.float64).tolist()}
                 for x in a["area"]]
        results[key] = prediction(segs, a["topology_lsls"].astype(float).tolist(), areas)
    items = [x for r in results.values() for x in r["predictions"]["lane_segment"] + r["predictions"]["area"]]
    for x, c in zip(items, rnd.sample(range(1, 10 ** 6), len(items))):
        x["confidence"] = c / 10 ** 6
    return results


def prediction(segs, topo, areas):
    n = len(segs)
    return {"predictions": {
        "lane_segment": [dict(s, id=i, confidence=None) for i, s in enumerate(segs)],
        "area": [dict(x, id=i, confidence=None) for i, x in enumerate(areas)],
        "traffic_element": [], "topology_lsls": topo, "topology_lste": [[] for _ in range(n)]}}


def evaluator_gt(gt, fix):
    """The ground truth as collect() hands it to the evaluator."""
    out = {}
    for key, f in gt.items():
        n = len(f["lane_segment"])
        out[key] = {"annotation": {
            "lane_segment": [{"id": i, **{name: fix(np.array(s[name]), 10) for name in LINES}}
                             for i, s in enumerate(f["lane_segment"])],
            "area": [{"id": i, "category": x["category"], "points": fix(np.array(x["points"]), 20)}
                     for i, x in enumerate(f["area"])],
            "traffic_element": [],
            "topology_lsls": np.array(f["topology_lsls"], dtype=np.int8).reshape(n, n),
            "topology_lste": np.zeros((n, 0), dtype=np.int8)}}
    return out


def evaluator_preds(results):
    out = {"method": "golden", "results": {}}
    for key, r in results.items():
        p = r["predictions"]
        n = len(p["lane_segment"])
        out["results"][key] = {"predictions": {
            "lane_segment": [{"id": s["id"], "confidence": s["confidence"],
                              **{name: np.array(s[name], dtype=np.float64) for name in LINES}}
                             for s in p["lane_segment"]],
            "area": [{"id": x["id"], "category": x["category"], "confidence": x["confidence"],
                      "points": np.array(x["points"], dtype=np.float64)} for x in p["area"]],
            "traffic_element": [],
            "topology_lsls": np.array(p["topology_lsls"], dtype=np.float64).reshape(n, n),
            "topology_lste": np.zeros((n, 0))}}
    return out


def evaluate(ev, dist, ev_gt, results):
    preds = evaluator_preds(results)
    metrics = ev.evaluate(ev_gt, preds, verbose=False)["OpenLane-V2 UniScore"]
    # Per threshold and per category, by the evaluator's own functions and distances.
    gts = {k: v["annotation"] for k, v in ev_gt.items()}
    prs = {k: v["predictions"] for k, v in evaluator_preds(results)["results"].items()}
    seg, area = {}, {}
    for k in gts:
        g, q = gts[k]["lane_segment"], prs[k]["lane_segment"]
        mask = dist.pairwise(g, q, dist.lane_segment_distance_c, relax=True) < ev.THRESHOLDS_LANESEG[-1]
        seg[k] = dist.pairwise(g, q, dist.lane_segment_distance, mask=mask, relax=True)
        area[k] = dist.pairwise(gts[k]["area"], prs[k]["area"], dist.area_distance)
    per = ev._mAP_over_threshold(gts, prs, seg, ev.THRESHOLDS_LANESEG, "lane_segment", lambda _: True, False)
    per_category = {name: float(ev._mAP_over_threshold(gts, prs, area, ev.THRESHOLDS_AREA, "area",
                                                       lambda x, c=c: x["category"] == c, False).mean())
                    for name, c in ev.AREA_CATEGOTY.items()}
    return {"DET_ls": float(metrics["DET_l"]), "DET_a": float(metrics["DET_a"]), "TOP_lsls": float(metrics["TOP_ll"]),
            "score": float(metrics["score"]),
            "DET_ls_per_threshold": {str(t): float(v) for t, v in zip(ev.THRESHOLDS_LANESEG, per)},
            "DET_a_per_category": per_category, "frames": len(ev_gt)}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--openlanev2", required=True)
    source = ap.add_mutually_exclusive_group(required=True)
    source.add_argument("--frames", action="append", help="a frames export (give two: A and B)")
    source.add_argument("--gt-json", help="the committed gt.json instead of the exports")
    ap.add_argument("--seed", type=int, default=53)
    a = ap.parse_args()
    import_evaluator(a.openlanev2)  # the stubs and the path
    ev = importlib.import_module("openlanev2.lanesegment.evaluation.evaluate")
    dist = importlib.import_module("openlanev2.lanesegment.evaluation.distance")
    fix = importlib.import_module("openlanev2.lanesegment.preprocessing.collect")._fix_pts_interpolate
    gt = read_exports(a.frames) if a.frames else json.load(open(a.gt_json))["frames"]
    ev_gt = evaluator_gt(gt, fix)
    files = {"pred.json": perturb(gt, a.seed), "pred-ties.json": ties(gt, a.seed * 7 + 1),
             "pred-copy.json": copy_of(ev_gt, a.seed)}
    expected = {name: evaluate(ev, dist, evaluator_gt(gt, fix), r) for name, r in files.items()}
    expected["made_by"] = ("make_golden.py: OpenLane-V2 f085b3d lanesegment evaluate() on gt.json and each file "
                           "(seed %d), numpy %s" % (a.seed, np.__version__))
    for name, doc in (("gt.json", {"frames": gt}), *((n, {"results": r}) for n, r in files.items()),
                      ("expected.json", expected)):
        with open(os.path.join(HERE, name), "w") as f:
            json.dump(doc, f, indent=None if name != "expected.json" else 1, sort_keys=True)
            f.write("\n")
    print(json.dumps(expected, indent=1))


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""Golden DET_l / TOP_ll values of the frames metrics, from OpenLane-V2's own evaluator.

Made once, committed beside this script, read by tests/unit/metrics/test_frames_golden.cpp.
The numbers are computed by the evaluator's code, run from its source tree:

  OpenDriveLab/OpenLane-V2  f085b3d (Apache-2.0), openlanev2/centerline/evaluation/evaluate.py

  /usr/bin/python3 make_golden.py --openlanev2 <OpenLane-V2 checkout> \
      --frames <frames export A> --frames <frames export B> [--seed 41]
  /usr/bin/python3 make_golden.py --openlanev2 <OpenLane-V2 checkout> --gt-json gt.json

(the second form reads the committed ground truth instead of the exports, and remakes
every file byte for byte).

Debian 12 packages used: python3-numpy, python3-scipy (the evaluator's cdist / euclidean),
python3-shapely and python3-tqdm (imported by the evaluator's package). Not packaged in
Debian, and stubbed or supplied here: `similaritymeasures` (the evaluator calls its
`frechet_dist(pred, gt, p=2)`, the discrete Frechet distance of Eiter & Mannila; supplied
below as that dynamic programme), `iso3166`, `cv2` and `ortools` (imported, unused by
the DET_l / TOP_ll evaluation), and the F-Score of `f_score.py` (a different metric, not computed). The
evaluator's `evaluate()` runs unchanged otherwise: DET_l is its 'OpenLane-V2 Score'/'DET_l',
TOP_ll its 'TOP_ll'; the per-threshold APs come from its `_mAP_over_threshold`.

Ground truth: the `annotation` of every record of the exports given (their `points`, as
`collect()` loads them: float32; `topology_lclc` as int8), keyed by sample token (the
second export's keys get a suffix "~B"). The exports used for the committed files:
`nsgraph frames --overlap keep` on the e2e test release and dataset
(tests/data/synth/e2e.json, tests/data/generate/e2e.json), window default (A) and
`--set window.x_min_m=-30 --set window.x_max_m=30 --set window.y_min_m=-15
--set window.y_max_m=15` (B): 50 frames.

Predictions (pred.json, an OpenLane-V2 results document in JSON) are perturbed copies, by
frame (seeded): exact copies; lanes shifted by 0.3–2.9 m; lanes dropped; extra lanes;
wrong topology (links flipped, probabilities spread); resampled to other point counts;
confidences shuffled. Confidences are distinct over the whole file and topology
probabilities distinct within a frame, so no order depends on how a sort breaks ties.

pred-b.json: the same perturbations drawn with the seed 7 × seed + 3.

pred-copy.json: the ground truth itself (links 1.0, others 0.0), distinct confidences.

pred-ties-all.json, pred-ties-half.json, pred-ties-distinct.json: ranking where confidences
tie, as OpenLane-V2's evaluator ranks them (numpy's default argsort, not stable beyond 16
values; docs/metrics.md "Frames", Ties). Every ground-truth lane predicted, moved by a
seeded distance (all: exactly 2.5 m, the rest 0-2.9 m), a tenth dropped, and in three of
ten lanes a second prediction near the same ground truth (a conflict: the one ranked first
takes it); links carried with probabilities from {1.0, 0.8} (ties within a row, rows of up
to 32) and some flipped. Confidences: all 0.9 (all); 0.7 on every other lane and distinct values
on the rest (half); distinct (distinct). Made with the evaluator run under Debian 12's numpy
1.24.2, whose argsort is the introsort of the numpy < 1.24 that OpenLane-V2 pins.

expected.json: per predictions file {"DET_l", "DET_l_per_threshold": {"1.0", "2.0", "3.0"},
"TOP_ll", "frames"}.
"""
import argparse
import glob
import json
import os
import random
import sys
import types

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def discrete_frechet(p, q, p_norm=2):
    """Discrete Frechet distance (Eiter & Mannila 1994), Euclidean: the DP over couplings."""
    p = np.asarray(p, dtype=np.float64)
    q = np.asarray(q, dtype=np.float64)
    n, m = len(p), len(q)
    d = np.sqrt(((p[:, None, :] - q[None, :, :]) ** 2).sum(-1))
    ca = np.full((n, m), np.inf)
    for i in range(n):
        for j in range(m):
            if i == 0 and j == 0:
                ca[i, j] = d[0, 0]
            elif i == 0:
                ca[i, j] = max(ca[0, j - 1], d[0, j])
            elif j == 0:
                ca[i, j] = max(ca[i - 1, 0], d[i, 0])
            else:
                ca[i, j] = max(min(ca[i - 1, j], ca[i - 1, j - 1], ca[i, j - 1]), d[i, j])
    return ca[n - 1, m - 1]


def import_evaluator(root):
    sm = types.ModuleType("similaritymeasures")
    sm.frechet_dist = lambda a, b, p=2: discrete_frechet(a, b, p)
    sys.modules["similaritymeasures"] = sm
    iso = types.ModuleType("iso3166")
    iso.countries = types.SimpleNamespace(get=lambda x: x)
    sys.modules["iso3166"] = iso
    sys.modules["cv2"] = types.ModuleType("cv2")
    for name in ("ortools", "ortools.graph", "ortools.graph.pywrapgraph"):  # the F-Score's matcher
        sys.modules[name] = types.ModuleType(name)
    sys.modules["ortools"].graph = sys.modules["ortools.graph"]
    sys.modules["ortools.graph"].pywrapgraph = sys.modules["ortools.graph.pywrapgraph"]
    sys.path.insert(0, root)
    import importlib
    ev = importlib.import_module("openlanev2.centerline.evaluation.evaluate")  # the module, not its function
    ev.f1.bench_one_submit = lambda gts, preds: float("nan")  # the F-Score: another metric
    return ev


def read_exports(dirs):
    gt = {}
    for k, d in enumerate(dirs):
        manifest = json.load(open(os.path.join(d, "manifest.json")))
        for f in manifest["files"]:
            if "/info/" not in f["path"]:
                continue
            r = json.load(open(os.path.join(d, f["path"])))
            a = r["annotation"]
            key = r["sample_token"] + ("" if k == 0 else "~" + "AB"[k])
            gt[key] = {"lane_centerline": [{"id": c["id"], "points": c["points"]} for c in a["lane_centerline"]],
                       "topology_lclc": a["topology_lclc"]}
    return dict(sorted(gt.items()))


def resample(points, n):
    pts = np.asarray(points, dtype=np.float64)
    seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    t = np.linspace(0.0, s[-1], n)
    return np.stack([np.interp(t, s, pts[:, i]) for i in range(3)], axis=1).tolist()


def perturb(gt, seed):
    rnd = random.Random(seed)
    results = {}
    kinds = ["copy", "shift", "drop", "extra", "topology", "points", "mixed"]
    for f, (key, frame) in enumerate(gt.items()):
        kind = kinds[f % len(kinds)]
        lanes, keep = [], []
        for i, c in enumerate(frame["lane_centerline"]):
            if kind in ("drop", "mixed") and rnd.random() < 0.3:
                continue
            pts = [list(p) for p in c["points"]]
            if kind in ("shift", "mixed") and rnd.random() < 0.8:
                d, a = rnd.uniform(0.3, 2.9), rnd.uniform(0, 6.283185307179586)
                pts = [[p[0] + d * np.cos(a), p[1] + d * np.sin(a), p[2]] for p in pts]
            if kind == "points":
                pts = resample(pts, rnd.choice([2, 5, 20, 40]))
            lanes.append({"id": len(lanes), "points": [[round(c, 4) for c in p] for p in pts]})
            keep.append(i)
        n_true = len(lanes)
        if kind in ("extra", "mixed"):
            for _ in range(rnd.randint(1, 4)):
                x0, y0 = rnd.uniform(-45, 40), rnd.uniform(-22, 22)
                h = rnd.uniform(0, 6.283185307179586)
                lanes.append({"id": len(lanes), "points": [[round(x0 + k * np.cos(h), 4), round(y0 + k * np.sin(h), 4),
                                                            0.0] for k in range(0, 11)]})
        n = len(lanes)
        topo = [[0.0] * n for _ in range(n)]
        gt_topo = frame["topology_lclc"]
        used = set()

        def prob(lo, hi):
            while True:
                v = round(rnd.uniform(lo, hi), 6)
                if v not in used and v != 0.5:
                    used.add(v)
                    return v
        for a in range(n):
            for b in range(n):
                linked = a < n_true and b < n_true and gt_topo[keep[a]][keep[b]] == 1
                if kind in ("topology", "mixed") and rnd.random() < 0.3:
                    linked = not linked
                if linked:
                    topo[a][b] = prob(0.51, 0.99) if kind in ("topology", "mixed") else prob(0.9, 1.0)
                else:
                    topo[a][b] = prob(0.0, 0.49) if rnd.random() < 0.2 else 0.0
        for lane in lanes:
            lane["confidence"] = None
        results[key] = {"predictions": {"lane_centerline": lanes, "traffic_element": [], "topology_lclc": topo,
                                        "topology_lcte": [[] for _ in range(n)]}}
    # Confidences distinct over the file; shuffled in the "shuffle" frames' order.
    all_lanes = [(k, l) for k, r in results.items() for l in r["predictions"]["lane_centerline"]]
    confidences = rnd.sample(range(1, 10 ** 6), len(all_lanes))
    for (k, lane), c in zip(all_lanes, confidences):
        lane["confidence"] = c / 10 ** 6
    return results


def copy_of(gt, seed):
    """The ground truth itself, confidences distinct, links 1 and non-links 0: scores 1."""
    rnd = random.Random(seed)
    results = {}
    for key, frame in gt.items():
        lanes = [{"id": c["id"], "points": c["points"]} for c in frame["lane_centerline"]]
        n = len(lanes)
        results[key] = {"predictions": {"lane_centerline": lanes, "traffic_element": [],
                                        "topology_lclc": [[float(v) for v in row] for row in frame["topology_lclc"]],
                                        "topology_lcte": [[] for _ in range(n)]}}
    all_lanes = [l for r in results.values() for l in r["predictions"]["lane_centerline"]]
    for lane, c in zip(all_lanes, rnd.sample(range(1, 10 ** 6), len(all_lanes))):
        lane["confidence"] = c / 10 ** 6
    return results


def ties(gt, seed, mode):
    """Predictions whose confidences tie (see the module's docstring)."""
    rnd = random.Random(seed)
    results = {}
    for key, frame in gt.items():
        lanes, source = [], []
        for i, c in enumerate(frame["lane_centerline"]):
            if rnd.random() < 0.1:
                continue
            copies = 2 if rnd.random() < 0.3 else 1
            for _ in range(copies):
                d = 2.5 if mode == "all" else rnd.uniform(0.0, 2.9)
                a = rnd.uniform(0, 6.283185307179586)
                pts = [[round(p[0] + d * np.cos(a), 4), round(p[1] + d * np.sin(a), 4), p[2]] for p in c["points"]]
                lanes.append({"id": len(lanes), "points": pts})
                source.append(i)
        n = len(lanes)
        gt_topo = frame["topology_lclc"]
        topo = [[0.0] * n for _ in range(n)]
        for a in range(n):
            for b in range(n):
                linked = gt_topo[source[a]][source[b]] == 1
                if rnd.random() < 0.05:
                    linked = not linked
                topo[a][b] = rnd.choice([1.0, 0.8]) if linked else 0.0
        for k, lane in enumerate(lanes):
            lane["confidence"] = {"all": 0.9, "half": 0.7 if k % 2 == 0 else None}.get(mode)
        results[key] = {"predictions": {"lane_centerline": lanes, "traffic_element": [], "topology_lclc": topo,
                                        "topology_lcte": [[] for _ in range(n)]}}
    if mode != "all":
        all_lanes = [l for r in results.values() for l in r["predictions"]["lane_centerline"]
                     if l["confidence"] is None]
        for lane, c in zip(all_lanes, rnd.sample(range(1, 10 ** 6), len(all_lanes))):
            lane["confidence"] = c / 10 ** 6
    return results


def evaluator_inputs(gt, results):
    """The evaluator's two arguments, as its collect() and a results pickle give them."""
    ground_truth = {}
    for key, frame in gt.items():
        ground_truth[key] = {"annotation": {
            "lane_centerline": [{"id": c["id"], "points": np.array(c["points"], dtype=np.float32)}
                                for c in frame["lane_centerline"]],
            "traffic_element": [],
            "topology_lclc": np.array(frame["topology_lclc"], dtype=np.int8).reshape(len(frame["lane_centerline"]), -1),
            "topology_lcte": np.zeros((len(frame["lane_centerline"]), 0), dtype=np.int8)}}
    preds = {"method": "golden", "e-mail": "-", "institution / company": "-", "country / region": "-",
             "authors": [], "results": {}}
    for key, r in results.items():
        p = r["predictions"]
        n = len(p["lane_centerline"])
        preds["results"][key] = {"predictions": {
            "lane_centerline": [{"id": l["id"], "points": np.array(l["points"], dtype=np.float64),
                                 "confidence": l["confidence"]} for l in p["lane_centerline"]],
            "traffic_element": [],
            "topology_lclc": np.array(p["topology_lclc"], dtype=np.float64).reshape(n, n),
            "topology_lcte": np.zeros((n, 0))}}
    return ground_truth, preds


def evaluate(ev, gt, results):
    ground_truth, preds = evaluator_inputs(gt, results)
    metrics = ev.evaluate(ground_truth, preds, verbose=False)["OpenLane-V2 Score"]
    # The per-threshold APs, by the evaluator's own function on its own distance matrices.
    gts = {k: v["annotation"] for k, v in ground_truth.items()}
    prs = {k: v["predictions"] for k, v in preds["results"].items()}
    dist = {}
    for k in gts:
        g = [x["points"] for x in gts[k]["lane_centerline"]]
        q = [x["points"] for x in prs[k]["lane_centerline"]]
        mask = ev.pairwise(g, q, ev.chamfer_distance, relax=True) < ev.THRESHOLDS_FRECHET[-1]
        dist[k] = ev.pairwise(g, q, ev.frechet_distance, mask=mask, relax=True)
    per = ev._mAP_over_threshold(gts, prs, dist, ev.THRESHOLDS_FRECHET, "lane_centerline", lambda _: True, False)
    return {"DET_l": float(metrics["DET_l"]), "TOP_ll": float(metrics["TOP_ll"]),
            "DET_l_per_threshold": {str(t): float(v) for t, v in zip(ev.THRESHOLDS_FRECHET, per)},
            "frames": len(gt)}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--openlanev2", required=True)
    source = ap.add_mutually_exclusive_group(required=True)
    source.add_argument("--frames", action="append", help="a frames export (give two: A and B)")
    source.add_argument("--gt-json", help="the committed gt.json instead of the exports")
    ap.add_argument("--seed", type=int, default=41)
    a = ap.parse_args()
    ev = import_evaluator(a.openlanev2)
    gt = read_exports(a.frames) if a.frames else json.load(open(a.gt_json))["frames"]
    results = perturb(gt, a.seed)
    results_b = perturb(gt, a.seed * 7 + 3)
    copy = copy_of(gt, a.seed)
    tied = {mode: ties(gt, a.seed * 11 + k, mode) for k, mode in enumerate(("all", "half", "distinct"))}
    expected = {"pred.json": evaluate(ev, gt, results), "pred-b.json": evaluate(ev, gt, results_b),
                "pred-copy.json": evaluate(ev, gt, copy),
                "made_by": "make_golden.py: OpenLane-V2 f085b3d evaluate() on gt.json and each file (seed %d), "
                           "numpy %s" % (a.seed, np.__version__)}
    for mode, results_t in tied.items():
        expected["pred-ties-%s.json" % mode] = evaluate(ev, gt, results_t)
    for name, doc in (("gt.json", {"frames": gt}), ("pred.json", {"results": results}),
                      ("pred-b.json", {"results": results_b}), ("pred-copy.json", {"results": copy}),
                      *(("pred-ties-%s.json" % m, {"results": r}) for m, r in tied.items()),
                      ("expected.json", expected)):
        with open(os.path.join(HERE, name), "w") as f:
            json.dump(doc, f, indent=None if name != "expected.json" else 1, sort_keys=True)
            f.write("\n")
    print(json.dumps(expected, indent=1))


if __name__ == "__main__":
    main()

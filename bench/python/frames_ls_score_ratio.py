"""`nsgraph score --frames` on lane segments and areas against OpenLane-V2 v2.1's own
lane-segment evaluator on the same 200 frames (the golden frames of
tests/data/golden/frames-ls, four times over with distinct keys): wall time of each in one
process (nsgraph.score_frames, reading the two files, against the evaluator's evaluate() on
its in-memory inputs, collect()'s resampling not counted), the ratio (target: nsgraph >= 20x
faster), and DET_ls / DET_a / TOP_lsls of each, which must agree to 1e-6.

OpenLane-V2's evaluator is optional, as for bench/python/frames_score_ratio.py: set
OPENLANEV2_ROOT to a checkout and install python3-scipy, python3-shapely and python3-tqdm;
without it the comparison prints an "optional" skip and exits 0.

usage: frames_ls_score_ratio.py --python-package build/python --out OUT.json [--copies 4]
"""
import argparse
import importlib
import json
import os
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
GOLDEN = os.path.join(HERE, "..", "..", "tests", "data", "golden", "frames-ls")
sys.path.insert(0, HERE)
from frames_score_ratio import golden_maker, replicate  # noqa: E402  (the same golden-set handling)
TARGET_RATIO = 20.0
METRICS = ("DET_ls", "DET_a", "TOP_lsls")


def evaluator():
    loaded, why = golden_maker(GOLDEN)
    if loaded is None:
        return None, why
    root, make_golden = loaded
    make_golden.import_evaluator(root)
    ev = importlib.import_module("openlanev2.lanesegment.evaluation.evaluate")
    fix = importlib.import_module("openlanev2.lanesegment.preprocessing.collect")._fix_pts_interpolate
    return (make_golden, ev, fix), None


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", required=True)
    ap.add_argument("--copies", type=int, default=4)
    ap.add_argument("--python-package", required=True, help="the folder holding the nsgraph package (build/python)")
    a = ap.parse_args()
    gt, pred = replicate(a.copies, GOLDEN)
    r = {"frames": len(gt), "target_ratio": TARGET_RATIO}
    sys.path.insert(0, a.python_package)
    import nsgraph
    with tempfile.TemporaryDirectory() as tmp:
        gt_file, pred_file = os.path.join(tmp, "gt.json"), os.path.join(tmp, "pred.json")
        json.dump({"frames": gt}, open(gt_file, "w"))
        json.dump({"results": pred}, open(pred_file, "w"))
        best = None
        for _ in range(5):
            t0 = time.perf_counter()
            ours = nsgraph.score_frames(gt_file, pred_file)["lane_segments"]
            s = time.perf_counter() - t0
            best = s if best is None else min(best, s)
        r["nsgraph"] = dict({m: ours[m] for m in METRICS}, wall_s=best,
                            note="nsgraph.score_frames in this process, files read, parsed and resampled included")
    loaded, why = evaluator()
    if loaded is None:
        r["openlanev2"] = None
        r["skipped"] = f"optional tool OpenLane-V2 evaluator not available: {why}"
        print(r["skipped"])
    else:
        make_golden, ev, fix = loaded
        ground_truth = make_golden.evaluator_gt(gt, fix)
        results = make_golden.evaluator_preds({k: {"predictions": v["predictions"]} for k, v in pred.items()})
        t0 = time.perf_counter()
        theirs = ev.evaluate(ground_truth, results, verbose=False)["OpenLane-V2 UniScore"]
        wall = time.perf_counter() - t0
        theirs = {"DET_ls": float(theirs["DET_l"]), "DET_a": float(theirs["DET_a"]), "TOP_lsls": float(theirs["TOP_ll"])}
        r["openlanev2"] = dict(theirs, wall_s=wall)
        r["ratio"] = wall / r["nsgraph"]["wall_s"]
        r["agree"] = all(abs(theirs[m] - r["nsgraph"][m]) <= 1e-6 for m in METRICS)
        r["pass"] = r["ratio"] >= TARGET_RATIO and r["agree"]
    json.dump(r, open(a.out, "w"), indent=1)
    print(json.dumps(r, indent=1))
    if r.get("pass") is False:
        print(f"frames_ls_score_ratio: target missed (ratio >= {TARGET_RATIO} and the metrics equal)", file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()

"""`nsgraph score --frames` against OpenLane-V2's own evaluator on the same 200 frames (the
golden frames of tests/data/golden/frames, four times over with distinct keys): wall time of
each in one process (nsgraph.score_frames, reading the two files, against the evaluator's
evaluate() on its in-memory inputs), the ratio (target: nsgraph >= 20x faster), the CLI's
whole-process time beside it, and the DET_l / TOP_ll of each, which must agree to 1e-6.

OpenLane-V2's evaluator is optional: set OPENLANEV2_ROOT to a checkout of
github:OpenDriveLab/OpenLane-V2 (its `openlanev2/` folder) and install python3-scipy,
python3-shapely and python3-tqdm (Debian); similaritymeasures, iso3166, cv2 and ortools are
supplied or stubbed as in tests/data/golden/frames/make_golden.py. Without it the comparison
prints an "optional" skip and exits 0.

usage: frames_score_ratio.py --nsgraph EXE --python-package build/python --out OUT.json [--copies 4]
"""
import argparse
import importlib.util
import json
import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
GOLDEN = os.path.join(HERE, "..", "..", "tests", "data", "golden", "frames")
TARGET_RATIO = 20.0


def replicate(copies, golden=GOLDEN):
    """The golden ground truth and pred.json `copies` times over, keys made distinct."""
    gt = json.load(open(os.path.join(golden, "gt.json")))["frames"]
    pred = json.load(open(os.path.join(golden, "pred.json")))["results"]
    g, p = {}, {}
    for c in range(copies):
        for k in gt:
            g[f"{k}~{c}"] = gt[k]
            p[f"{k}~{c}"] = pred[k]
    return g, p


def golden_maker(golden=GOLDEN):
    """(OpenLane-V2's root, the golden set's make_golden module), or (None, why not): the
    peer is optional."""
    root = os.environ.get("OPENLANEV2_ROOT")
    if not root or not os.path.isdir(os.path.join(root, "openlanev2")):
        return None, "OPENLANEV2_ROOT is not set to an OpenLane-V2 checkout"
    for module in ("numpy", "scipy", "shapely", "tqdm"):
        if importlib.util.find_spec(module) is None:
            return None, f"python3-{module} is not installed"
    spec = importlib.util.spec_from_file_location("make_golden_" + os.path.basename(golden),
                                                  os.path.join(golden, "make_golden.py"))
    make_golden = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(make_golden)
    return (root, make_golden), None


def evaluator():
    loaded, why = golden_maker()
    if loaded is None:
        return None, why
    root, make_golden = loaded
    return (make_golden, make_golden.import_evaluator(root)), None


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--nsgraph", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--copies", type=int, default=4)
    ap.add_argument("--python-package", required=True, help="the folder holding the nsgraph package (build/python)")
    a = ap.parse_args()
    gt, pred = replicate(a.copies)
    r = {"frames": len(gt), "target_ratio": TARGET_RATIO}
    with tempfile.TemporaryDirectory() as tmp:
        gt_file, pred_file = os.path.join(tmp, "gt.json"), os.path.join(tmp, "pred.json")
        json.dump({"frames": gt}, open(gt_file, "w"))
        json.dump({"results": pred}, open(pred_file, "w"))
        best = None
        for _ in range(3):
            t0 = time.perf_counter()
            out = subprocess.run([a.nsgraph, "score", "--quiet", "--frames", "--ground-truth", gt_file,
                                  "--submission", pred_file], capture_output=True, text=True, check=True).stdout
            s = time.perf_counter() - t0
            best = s if best is None else min(best, s)
        report = json.loads(out)
        r["nsgraph_cli"] = {"wall_s": best, "DET_l": report["DET_l"], "TOP_ll": report["TOP_ll"],
                            "note": "the whole process: start (dynamic linking of the toolkit) included"}
        # In one process, as the evaluator is timed: nsgraph.score_frames reads both files too.
        sys.path.insert(0, a.python_package)
        import nsgraph
        best = None
        for _ in range(5):
            t0 = time.perf_counter()
            inproc = nsgraph.score_frames(gt_file, pred_file)
            s = time.perf_counter() - t0
            best = s if best is None else min(best, s)
        r["nsgraph"] = {"wall_s": best, "DET_l": inproc["DET_l"], "TOP_ll": inproc["TOP_ll"],
                        "note": "nsgraph.score_frames in this process, files read and parsed included"}
    loaded, why = evaluator()
    if loaded is None:
        r["openlanev2"] = None
        r["skipped"] = f"optional tool OpenLane-V2 evaluator not available: {why}"
        print(r["skipped"])
    else:
        make_golden, ev = loaded
        ground_truth, results = make_golden.evaluator_inputs(gt, pred)  # in memory, as from its pickles
        t0 = time.perf_counter()
        theirs = ev.evaluate(ground_truth, results, verbose=False)["OpenLane-V2 Score"]
        theirs = {"DET_l": float(theirs["DET_l"]), "TOP_ll": float(theirs["TOP_ll"])}
        r["openlanev2"] = {"wall_s": time.perf_counter() - t0, "DET_l": theirs["DET_l"], "TOP_ll": theirs["TOP_ll"]}
        r["ratio"] = r["openlanev2"]["wall_s"] / r["nsgraph"]["wall_s"]
        r["agree"] = all(abs(theirs[m] - x[m]) <= 1e-6 for x in (report, inproc) for m in ("DET_l", "TOP_ll"))
        r["pass"] = r["ratio"] >= TARGET_RATIO and r["agree"]
    json.dump(r, open(a.out, "w"), indent=1)
    print(json.dumps(r, indent=1))
    if r.get("pass") is False:
        print(f"frames_score_ratio: target missed (ratio >= {TARGET_RATIO} and DET_l/TOP_ll equal)", file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()

"""Chooses the relationship head's decision point on training tiles and bakes it into the
model, so both predictors (ONNX in C++, PyTorch in Python) use it unchanged.

    /usr/bin/python3 -m nsgraph.models.calibrate --model run/model.pt --dataset D [--split train]

The head is trained with positives weighted by the class ratio, on ground-truth-like and
its own anchors; at test time the graph keeps pairs scoring ≥ 0.5 (lib/model net_graph),
then prunes. Which cut gives the best graphs is an empirical question: this tries shifts of
the head's logit on whole training tiles (every --every-th, no augmentation), scores the
graphs with the benchmark's own metrics (nsgraph.scoring.score_tile) and keeps the shift
with the highest mean APLS + TOPO F1. The shift is added to the head's last bias (model.pt
records it; a second run starts from the uncalibrated head). The test split is never seen.
"""
import argparse
import json
import os
import sys
import time

import numpy as np
import torch

from .cli_help import DefaultsHelpFormatter
from ..progress import Progress
from .. import _nsgraph
from ..dataset import Dataset
from ..scoring import score_tile
from .predict import anchors_and_pair_inputs, load

SHIFTS = (-0.7, 0.0, 0.35, 0.7, 1.05, 1.4, 1.75, 2.1, 2.45, 2.8, 3.5)   # added to the pair logit
LAST_BIAS = "mlp.4.bias"                                       # PairHead's output layer


def tile_candidates(dense, pairs_head, tile):
    """Anchors, pairs and the head's logits of one tile (what net_graph needs)."""
    a, x, size = anchors_and_pair_inputs(dense, tile)
    with torch.no_grad():
        logits = pairs_head.head(torch.from_numpy(x))[:, 0].double() if len(x) else torch.zeros(0, dtype=torch.float64)
    return a, logits, size


def evaluate(candidates, shifts):
    """{shift: (mean APLS, mean TOPO F1)} over the tiles where each is defined."""
    out = {}
    for s in shifts:
        apls, topo = [], []
        for tile, a, logits, size in candidates:
            scores = torch.sigmoid(logits + s).numpy()
            g = _nsgraph.net_graph(a["points"], a["scores"], a["votes"], a["pairs"], scores, size)
            m = score_tile(tile["graph"], (g["nodes"], g["edges"]))
            if m.get("apls") is not None:
                apls.append(m["apls"])
            if m.get("topo_f1") is not None:
                topo.append(m["topo_f1"])
        out[s] = (float(np.mean(apls)) if apls else 0.0, float(np.mean(topo)) if topo else 0.0)
    return out


def calibrate(model_path, dataset, split="train", every=4, threads=1, progress=False):
    torch.set_num_threads(threads)
    state = torch.load(model_path)
    previous = float(state.get("pair_logit_shift", 0.0))
    state["head"][LAST_BIAS] = state["head"][LAST_BIAS] - previous
    tmp = model_path + ".uncalibrated.tmp"
    torch.save(state, tmp)
    try:
        dense, pairs_head = load(tmp)
    finally:
        os.remove(tmp)
    tiles = Dataset(dataset, split)
    picked = range(0, len(tiles), every)
    candidates = []
    with Progress("calibrate tiles", len(picked), enabled=progress) as bar:
        for i in picked:
            tile = tiles[i]
            candidates.append((tile, *tile_candidates(dense, pairs_head, tile)))
            bar.advance()
    results = evaluate(candidates, SHIFTS)
    best = max(SHIFTS, key=lambda s: (round(sum(results[s]), 9), -abs(s)))
    state["head"][LAST_BIAS] = state["head"][LAST_BIAS] + best
    state["pair_logit_shift"] = best
    out = model_path + ".tmp"
    torch.save(state, out)
    os.replace(out, model_path)
    return {"split": split, "tiles": len(candidates), "every": every, "shift": best,
            "mean_apls_topo_f1": {f"{s:+.2f}": [round(v, 4) for v in results[s]] for s in SHIFTS}}


def main(argv=None):
    p = argparse.ArgumentParser(prog="python -m nsgraph.models.calibrate", description=__doc__.split("\n\n")[0],
                                formatter_class=DefaultsHelpFormatter)
    p.add_argument("--model", required=True, help="model.pt from nsgraph.models.train (rewritten)")
    p.add_argument("--dataset", required=True, help="dataset folder (manifest.json)")
    p.add_argument("--split", default="train", help="never the split you report on")
    p.add_argument("--every", type=int, default=4, help="use every N-th tile of the split")
    p.add_argument("--threads", type=int, default=1, help="torch threads")
    p.add_argument("--quiet", action="store_true", help="no progress lines")
    a = p.parse_args(argv)
    if a.every < 1:
        p.error("--every: expected ≥ 1")
    t0 = time.monotonic()
    report = calibrate(a.model, a.dataset, a.split, a.every, a.threads, progress=not a.quiet)
    report["seconds"] = round(time.monotonic() - t0, 1)
    with open(os.path.join(os.path.dirname(os.path.abspath(a.model)), "calibration.json"), "w") as f:
        json.dump(report, f, indent=1)
    if not a.quiet:
        print(f"calibrated the relationship head on {report['tiles']} '{a.split}' tiles: logit shift "
              f"{report['shift']:+.2f} (mean APLS, TOPO F1 per shift: {report['mean_apls_topo_f1']})")
    return 0


if __name__ == "__main__":
    sys.exit(main())

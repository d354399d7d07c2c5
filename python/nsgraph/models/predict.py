"""LaneGraphNet's graphs with PyTorch (the Python predictor): the network's dense heads and
relationship head in torch, anchors, pair pooling and the graph in the C++ library (the
post-processing `nsgraph predict --model M.onnx` runs).

    /usr/bin/python3 -m nsgraph.models.predict --model run/model.pt --dataset D --split test --out pred.json
"""
import argparse
import sys
import time

import numpy as np
import torch

from .cli_help import DefaultsHelpFormatter
from ..progress import Progress
from .. import _nsgraph
from ..dataset import Dataset
from ..scoring import write_submission
from .lanegraphnet import DenseExport, LaneGraphNet, PairExport, PairHead, encode_inputs


def load(path):
    """(dense, pairs) modules in eval mode from a model.pt of nsgraph.models.train."""
    state = torch.load(path)
    net, head = LaneGraphNet(), PairHead()
    net.load_state_dict(state["net"])
    head.load_state_dict(state["head"])
    return DenseExport(net).eval(), PairExport(head).eval()


def anchors_and_pair_inputs(dense, tile):
    """The dense heads on one dataset tile: (anchors as net_anchors gives them, the candidate
    pairs' inputs (P, 65) for the relationship head, the tile's side in px)."""
    inputs = {k: torch.from_numpy(v)[None] for k, v in encode_inputs(tile).items()}
    size = int(tile["coverage"].shape[0])
    with torch.no_grad():
        heat, offset, direction, feats = (t[0].numpy() for t in dense(**inputs))
    a = _nsgraph.net_anchors(heat[0], offset, direction, size)
    return a, _nsgraph.net_pair_inputs(feats, a["points"], a["pairs"]), size


def predict_tile(dense, pairs_head, tile):
    """{nodes (N, 2) u, v; edges (E, 2); node_scores; edge_scores} of one dataset tile."""
    a, x, size = anchors_and_pair_inputs(dense, tile)
    with torch.no_grad():
        scores = pairs_head(torch.from_numpy(x))[:, 0].double().numpy() if len(x) else np.zeros(0)
    return _nsgraph.net_graph(a["points"], a["scores"], a["votes"], a["pairs"], scores, size)


def predict_split(model_path, dataset, split, threads=2, progress=False):
    torch.set_num_threads(threads)
    dense, pairs_head = load(model_path)
    tiles = Dataset(dataset, split)
    out = {}
    with Progress(f"predict {split}", len(tiles), enabled=progress) as bar:
        for i in range(len(tiles)):
            tile = tiles[i]
            out[tile["key"]] = predict_tile(dense, pairs_head, tile)
            bar.advance()
    return out


def main(argv=None):
    p = argparse.ArgumentParser(prog="python -m nsgraph.models.predict", description=__doc__.split("\n\n")[0],
                                formatter_class=DefaultsHelpFormatter)
    p.add_argument("--model", required=True, help="model.pt from nsgraph.models.train")
    p.add_argument("--dataset", required=True, help="dataset folder (manifest.json)")
    p.add_argument("--split", default="test", help="the split to predict")
    p.add_argument("--out", required=True, help="submission JSON to write")
    p.add_argument("--threads", type=int, default=2, help="torch threads")
    p.add_argument("--quiet", action="store_true", help="no progress lines")
    a = p.parse_args(argv)
    t0 = time.monotonic()
    graphs = predict_split(a.model, a.dataset, a.split, a.threads, progress=not a.quiet)
    s = time.monotonic() - t0
    write_submission(a.out, {k: (g["nodes"], g["edges"]) for k, g in graphs.items()})
    if not a.quiet:
        print(f"predicted {len(graphs)} tiles of '{a.split}' in {s:.1f} s ({len(graphs) / max(s, 1e-9):.1f} tiles/s)"
              f" → {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

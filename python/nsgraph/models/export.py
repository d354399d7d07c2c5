"""Exports a trained LaneGraphNet to ONNX for `nsgraph predict --model M.onnx` (OpenCV dnn):
M.onnx the dense heads (inputs lidar, rgb, semantic, vehicle (1, C, H, W); outputs heat,
offset, direction, features), M.pairs.onnx the relationship head (input pairs (N, 65),
output score (N, 1)). Opset 11, ops OpenCV 4.6's dnn loads.

    /usr/bin/python3 -m nsgraph.models.export --model run/model.pt --out run/lanegraphnet.onnx
"""
import argparse
import contextlib
import os
import sys

import torch

from .cli_help import DefaultsHelpFormatter
from .lanegraphnet import INPUTS, PAIR_INPUTS
from .predict import load

OPSET = 11


@contextlib.contextmanager
def _distinct_initializers():
    """torch's exporter merges equal initializers into Identity nodes, which OpenCV 4.6's
    ONNX importer rejects; keep them apart while exporting."""
    c = torch._C
    original = c._jit_pass_onnx_deduplicate_initializers
    c._jit_pass_onnx_deduplicate_initializers = lambda graph, params, training: params
    try:
        yield
    finally:
        c._jit_pass_onnx_deduplicate_initializers = original


def export(model_path, out_path, tile_size_px=None):
    if not out_path.endswith(".onnx"):
        raise ValueError(f"--out {out_path}: expected a file name ending in .onnx")
    state = torch.load(model_path)
    size = int(tile_size_px or state.get("tile_size_px", 256))
    dense, pairs = load(model_path)
    dummy = tuple(torch.zeros(1, c, size, size) for c in INPUTS.values())
    pairs_path = out_path[:-len(".onnx")] + ".pairs.onnx"
    for module, args, path, names, outs, dynamic in (
            (dense, dummy, out_path, list(INPUTS), ["heat", "offset", "direction", "features"], None),
            (pairs, (torch.zeros(2, PAIR_INPUTS),), pairs_path, ["pairs"], ["score"], {"pairs": {0: "n"}, "score": {0: "n"}})):
        tmp = path + ".tmp"
        with _distinct_initializers():
            torch.onnx.export(module, args, tmp, input_names=names, output_names=outs, opset_version=OPSET,
                              dynamic_axes=dynamic, do_constant_folding=True)
        os.replace(tmp, path)
    return out_path, pairs_path


def main(argv=None):
    p = argparse.ArgumentParser(prog="python -m nsgraph.models.export", description=__doc__.split("\n\n")[0],
                                formatter_class=DefaultsHelpFormatter)
    p.add_argument("--model", required=True, help="model.pt from nsgraph.models.train")
    p.add_argument("--out", required=True, help="M.onnx (M.pairs.onnx is written next to it)")
    p.add_argument("--tile-size", type=int, default=0, help="input size in px (default: the training tiles')")
    a = p.parse_args(argv)
    dense, pairs = export(a.model, a.out, a.tile_size or None)
    print(f"exported {dense} and {pairs}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

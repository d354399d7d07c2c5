#!/usr/bin/env python3
"""Writes the tiny ONNX models of the `segment` tests (tests/unit/segment), committed next to
this script: run it with Debian's python3-onnx (`python3 make_tiny_models.py`) to remake them.

synth-colours.onnx: a nearest-colour classifier of the synthetic renderer's surfaces
(lib/synth/src/camera_sim.cpp ground_base_rgb, the darker vertical faces of raised ground,
the sky gradient's ends, a ramp of building wall shades (lib/synth/src/world_surface.cpp); car paints
of lib/synth/src/traffic.cpp that no surface shares). Input 1x3xHxW RGB scaled to 0..1 (the labels file feeds it at
full size: no resampling blends the stripes of a crosswalk into a curb's grey); one
1x1 convolution gives, per channel c with colour m_c, the score 2 m_c.x - |m_c|^2, which
is -|x - m_c|^2 up to a term common to all channels, so the argmax is the nearest colour.
synth-colours.json maps the channels to our classes.

flat-output.onnx: the same convolution followed by Flatten, an output of shape N x (C*H*W)
that `segment` must refuse (not N x C x h x w).
"""
import json
import os

import numpy as np
import onnx
from onnx import TensorProto, helper, numpy_helper

HERE = os.path.dirname(os.path.abspath(__file__))

# (name, RGB, our class)
COLOURS = [
    ("asphalt", (84, 84, 88), "road"),
    ("paint_white", (232, 232, 226), "lane_marking"),
    ("paint_yellow", (226, 186, 40), "lane_marking"),
    ("crosswalk_paint", (238, 238, 232), "crosswalk"),
    ("sidewalk", (190, 184, 174), "sidewalk"),
    ("curb_top", (160, 160, 156), "curb"),
    ("terrain", (118, 112, 64), "terrain"),
    ("vegetation", (58, 112, 44), "vegetation"),
    ("sky_horizon", (200, 214, 228), "sky_other"),
    ("sky_zenith", (62, 120, 196), "sky_other"),
    ("car_red", (180, 20, 20), "car"),
    ("car_blue", (20, 40, 160), "car"),
    # Vertical faces of raised ground are drawn at 0.75 of the top's colour.
    ("sidewalk_face", (142, 138, 130), "sidewalk"),
    ("curb_face", (120, 120, 117), "curb"),
    # Building walls: (s, 0.9 s, 0.8 s) for s in 110..200, times a shading factor 0.45..1.
    ("building_70", (70, 63, 56), "building"),
    ("building_100", (100, 90, 80), "building"),
    ("building_130", (130, 117, 104), "building"),
    ("building_160", (160, 144, 128), "building"),
    ("building_190", (190, 171, 152), "building"),
]


def conv_graph(flatten):
    m = np.array([c for _, c, _ in COLOURS], dtype=np.float32) / 255.0  # K x 3
    weight = (2.0 * m).reshape(len(COLOURS), 3, 1, 1).astype(np.float32)
    bias = (-(m * m).sum(axis=1)).astype(np.float32)
    nodes = [helper.make_node("Conv", ["image", "weight", "bias"], ["scores" if not flatten else "conv"], kernel_shape=[1, 1])]
    out_shape = [1, len(COLOURS), "h", "w"]
    if flatten:
        nodes.append(helper.make_node("Flatten", ["conv"], ["scores"], axis=1))
        out_shape = [1, "n"]
    graph = helper.make_graph(
        nodes,
        "synth_colours" if not flatten else "flat_output",
        [helper.make_tensor_value_info("image", TensorProto.FLOAT, [1, 3, "h", "w"])],
        [helper.make_tensor_value_info("scores", TensorProto.FLOAT, out_shape)],
        [numpy_helper.from_array(weight, "weight"), numpy_helper.from_array(bias, "bias")],
    )
    model = helper.make_model(graph, producer_name="nsgraph tests", opset_imports=[helper.make_opsetid("", 11)])
    model.ir_version = 6  # what OpenCV 4.6's ONNX importer reads
    onnx.checker.check_model(model)
    return model


def main():
    onnx.save(conv_graph(False), os.path.join(HERE, "synth-colours.onnx"))
    onnx.save(conv_graph(True), os.path.join(HERE, "flat-output.onnx"))
    labels = {
        "schema_version": "1",
        "name": "synthetic renderer colours (tests)",
        "source": "tests/data/segment/make_tiny_models.py",
        "input": {"width": 1600, "height": 900, "rgb": True, "scale": 1.0 / 255.0, "mean": [0.0, 0.0, 0.0], "std": [1.0, 1.0, 1.0]},
        "classes": {str(i): cls for i, (_, _, cls) in enumerate(COLOURS)},
        "source_classes": {str(i): name for i, (name, _, _) in enumerate(COLOURS)},
    }
    with open(os.path.join(HERE, "synth-colours.json"), "w") as f:
        json.dump(labels, f, indent=2)
        f.write("\n")


if __name__ == "__main__":
    main()

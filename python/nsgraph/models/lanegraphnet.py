"""LaneGraphNet sized for a 2-core CPU (see docs/lanegraphnet.md).

One small convolutional encoder per modality (LiDAR intensity, RGB, semantics one-hot,
vehicle heading as sin/cos + presence), concatenated after each encoder's 4th convolution
(stride 4), a shared trunk with one coarser level, and four dense heads at stride 4:

- anchor heatmap (sigmoid) + sub-pixel offset (in cells): the anchor proposals, in place of
  the paper's region proposal network;
- LaneDirNet: a pyramid-pooling head (fixed average pools of 2, 4, 8 and 16 cells,
  upsampled back) with the paper's 19 classes (18 bins of 20° + background), softmax;
- pair features: the map the relationship head pools at both anchors and along the segment.

The relationship head (PairHead) scores candidate anchor pairs from those pooled features.
Only ops OpenCV 4.6's dnn loads are used (Conv, BatchNorm, ReLU, Concat, AveragePool with
fixed kernels, Resize by a fixed scale, Sigmoid, Softmax, Gemm).
"""
import numpy as np
import torch
from torch import nn
from torch.nn import functional as F

from .. import _nsgraph

STRIDE = 4                      # output cell = 4 × 4 px (0.8 m)
TILE_MULTIPLE = 64              # the pyramid's largest pool (16 cells) must divide the map
SEMANTIC_CLASSES = len(_nsgraph.SEMANTIC_CLASSES)  # one-hot channels (nsg/core/semantic_classes.h)
DIRECTION_CLASSES = _nsgraph.DIRECTION_CLASSES      # 18 bins of 20° + background (lib/model direction.h)
PAIR_FEATURES = 16              # channels of the pair-feature map
SEGMENT_SAMPLES = 5             # samples along a pair's segment, both ends included
INPUTS = {"lidar": 2, "rgb": 3, "semantic": SEMANTIC_CLASSES, "vehicle": 3}


def encode_inputs(tile):
    """The network's inputs from a tile dict (numpy layers as nsgraph.Dataset returns them;
    a missing modality is "no data"). Returns {name: float32 (C, H, W)}; the C++
    predictor (lib/model onnx_net.cpp) builds the same arrays."""
    h, w = tile["coverage"].shape
    lidar = tile.get("lidar", np.zeros((h, w), np.uint8))
    rgb = tile.get("rgb", np.zeros((h, w, 3), np.uint8))
    sem = tile.get("semantic", np.full((h, w), 255, np.uint8))
    veh = tile.get("vehicle", np.full((h, w), -1.0, np.float32))
    out = {"lidar": np.stack([lidar.astype(np.float32) / np.float32(255.0),
                              (lidar > 0).astype(np.float32)]),
           "rgb": (rgb.astype(np.float32) / np.float32(255.0)).transpose(2, 0, 1)}
    one_hot = np.zeros((SEMANTIC_CLASSES, h, w), np.float32)
    for c in range(SEMANTIC_CLASSES):
        one_hot[c] = sem == c
    out["semantic"] = one_hot
    has = veh >= 0
    angle = 2.0 * np.pi * np.where(has, veh, 0.0).astype(np.float64)
    out["vehicle"] = np.stack([np.where(has, np.sin(angle), 0.0), np.where(has, np.cos(angle), 0.0),
                               has.astype(np.float64)]).astype(np.float32)
    return {k: np.ascontiguousarray(v) for k, v in out.items()}


def conv_bn(cin, cout, stride=1, dilation=1):
    return nn.Sequential(nn.Conv2d(cin, cout, 3, stride, padding=dilation, dilation=dilation, bias=False),
                         nn.BatchNorm2d(cout), nn.ReLU(inplace=True))


class Encoder(nn.Module):
    """Four 3 × 3 convolutions, the first two with stride 2 (nothing runs at full
    resolution: CPU time): (C, H, W) → (width, H/4, W/4)."""

    def __init__(self, cin, width):
        super().__init__()
        self.layers = nn.Sequential(conv_bn(cin, 16, stride=2), conv_bn(16, 16, stride=2), conv_bn(16, 16),
                                    conv_bn(16, width))

    def forward(self, x):
        return self.layers(x)


class PyramidPooling(nn.Module):
    """PSPNet's pyramid pooling with fixed kernels (k × k cells averaged, 1 × 1 conv,
    upsampled by k): the map's size must be a multiple of the largest k."""

    def __init__(self, cin, branch, kernels=(2, 4, 8, 16)):
        super().__init__()
        self.kernels = kernels
        self.branches = nn.ModuleList(
            nn.Sequential(nn.Conv2d(cin, branch, 1, bias=False), nn.BatchNorm2d(branch), nn.ReLU(inplace=True))
            for _ in kernels)

    def forward(self, x):
        outs = [x]
        for k, branch in zip(self.kernels, self.branches):
            y = branch(F.avg_pool2d(x, k, k))
            outs.append(F.interpolate(y, scale_factor=k, mode="nearest"))
        return torch.cat(outs, 1)


class LaneGraphNet(nn.Module):
    """The dense part: inputs (B, C_m, H, W) per modality → heat (B, 1, H/4, W/4) in
    [0, 1], offset (B, 2, …) in cells, direction probabilities (B, 19, …), pair features
    (B, 16, …)."""

    def __init__(self, width=16, trunk=32):
        super().__init__()
        self.encoders = nn.ModuleDict({m: Encoder(c, width) for m, c in INPUTS.items()})
        self.fuse = nn.Sequential(conv_bn(width * len(INPUTS), trunk), conv_bn(trunk, trunk, dilation=2))
        self.down = nn.Sequential(conv_bn(trunk, trunk, stride=2), conv_bn(trunk, trunk, dilation=2))
        self.merge = conv_bn(2 * trunk, trunk)
        self.anchor = nn.Sequential(conv_bn(trunk, 24), nn.Conv2d(24, 3, 1))
        self.psp = PyramidPooling(trunk, 8)
        self.direction = nn.Sequential(conv_bn(trunk + 4 * 8, 32), nn.Conv2d(32, DIRECTION_CLASSES, 1))
        self.pair = nn.Sequential(conv_bn(trunk, 24), nn.Conv2d(24, PAIR_FEATURES, 1))
        # Anchors are rare: start the heatmap low (CenterNet's prior).
        nn.init.constant_(self.anchor[1].bias, 0.0)
        with torch.no_grad():
            self.anchor[1].bias[0] = -2.19

    def forward(self, lidar, rgb, semantic, vehicle):
        x = torch.cat([self.encoders["lidar"](lidar), self.encoders["rgb"](rgb),
                       self.encoders["semantic"](semantic), self.encoders["vehicle"](vehicle)], 1)
        x = self.fuse(x)
        coarse = F.interpolate(self.down(x), scale_factor=2, mode="nearest")
        x = self.merge(torch.cat([x, coarse], 1))
        a = self.anchor(x)
        heat_logit, offset = a[:, :1], a[:, 1:]
        direction_logit = self.direction(self.psp(x))
        return heat_logit, offset, direction_logit, self.pair(x)


class DenseExport(nn.Module):
    """What the ONNX dense graph computes: probabilities instead of logits."""

    def __init__(self, net):
        super().__init__()
        self.net = net

    def forward(self, lidar, rgb, semantic, vehicle):
        heat_logit, offset, direction_logit, pair = self.net(lidar, rgb, semantic, vehicle)
        return torch.sigmoid(heat_logit), offset, torch.softmax(direction_logit, 1), pair


PAIR_INPUTS = 4 * PAIR_FEATURES + 1


class PairHead(nn.Module):
    """The relationship network: P(has-connection) of an anchor pair from its pooled
    features (N, 4·16 + 1) — see pair_inputs."""

    def __init__(self, hidden=64):
        super().__init__()
        self.mlp = nn.Sequential(nn.Linear(PAIR_INPUTS, hidden), nn.ReLU(inplace=True), nn.Linear(hidden, 32),
                                 nn.ReLU(inplace=True), nn.Linear(32, 1))

    def forward(self, x):
        return self.mlp(x)


class PairExport(nn.Module):
    def __init__(self, head):
        super().__init__()
        self.head = head

    def forward(self, x):
        return torch.sigmoid(self.head(x))


def _bilinear(features, cu, cv):
    """features (C, h, w) sampled at cell coordinates (K,), clamped into the map
    (as lib/model net_graph.cpp does)."""
    _, h, w = features.shape
    cu = cu.clamp(0.0, w - 1.0)
    cv = cv.clamp(0.0, h - 1.0)
    u0 = cu.floor().clamp(max=max(w - 2, 0)).long()
    v0 = cv.floor().clamp(max=max(h - 2, 0)).long()
    fu = (cu - u0).unsqueeze(0)
    fv = (cv - v0).unsqueeze(0)
    u1 = (u0 + 1).clamp(max=w - 1)
    v1 = (v0 + 1).clamp(max=h - 1)
    f = features
    return ((1 - fv) * ((1 - fu) * f[:, v0, u0] + fu * f[:, v0, u1]) + fv * ((1 - fu) * f[:, v1, u0] + fu * f[:, v1, u1]))


def pair_inputs(features, points_px, pairs, radius_px):
    """Differentiable twin of lib/model's net_pair_inputs (the C++ predictor's): for each
    pair (a, b) of anchors (pixel coordinates), the feature map sampled bilinearly at
    SEGMENT_SAMPLES points from a to b; the row is [f(a) + f(b), |f(a) − f(b)|, mean and
    max over the interior samples, length / radius]. features: (C, h, w) tensor."""
    pts = torch.as_tensor(points_px, dtype=features.dtype)
    pr = torch.as_tensor(pairs, dtype=torch.long).reshape(-1, 2)
    if len(pr) == 0:
        return features.new_zeros((0, PAIR_INPUTS))
    a, b = pts[pr[:, 0]], pts[pr[:, 1]]
    t = torch.linspace(0.0, 1.0, SEGMENT_SAMPLES, dtype=features.dtype)
    p = a[:, None, :] + (b - a)[:, None, :] * t[None, :, None]           # (N, S, 2) px
    cells = (p - (STRIDE - 1) / 2.0) / STRIDE
    s = _bilinear(features, cells[..., 0].reshape(-1), cells[..., 1].reshape(-1))
    s = s.reshape(features.shape[0], len(pr), SEGMENT_SAMPLES).permute(1, 2, 0)  # (N, S, C)
    fa, fb, mid = s[:, 0], s[:, -1], s[:, 1:-1]
    length = torch.linalg.norm(b - a, dim=1, keepdim=True) / radius_px
    return torch.cat([fa + fb, (fa - fb).abs(), mid.mean(1), mid.amax(1), length], 1)


def options():
    """The C++ post-processing's options (lib/model net_graph.h), as a dict."""
    return _nsgraph.net_graph_options()

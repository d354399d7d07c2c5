#!/usr/bin/env python3
"""A tiny LaneDirNet in PyTorch on a NuScenesGraph dataset, end to end through nsgraph:

  nsgraph.torch.TorchDataset (+ augmentations) → labels from nsgraph.adaptive_ground_truth
  (each grid cell projected onto its nearest lane: the lane's direction, or background)
  → a small conv net trained a few steps → per-cell directions on the test tiles → a graph
  (each lane cell linked to the cell its direction points to) → nsgraph.write_submission
  → nsgraph.score.

  PYTHONPATH=build/python /usr/bin/python3 examples/train_lanedir.py --dataset DATASET --steps 50

It shows the API, not a good model: a few hundred steps on the demo dataset give a graph
that scores, not one that competes with `nsgraph train`.
"""
import argparse
import json
import math
import os
import sys

import numpy as np
import torch
from torch import nn

import nsgraph
import nsgraph.torch as ntorch

BINS = 8            # direction classes of 45°, plus background (class BINS)
STRIDE = 4          # the net predicts one cell per STRIDE × STRIDE pixels
LANE_RADIUS_PX = 6  # cells within this distance of a lane are lane cells


def cell_centres(size):
    c = np.arange(STRIDE / 2 - 0.5, size, STRIDE)
    u, v = np.meshgrid(c, c)
    return np.stack([u.ravel(), v.ravel()], axis=1)


def direction_labels(nodes, edges, tokens, size):
    """Per-cell class: the direction bin of the lane a cell projects onto (adaptive ground
    truth), or background."""
    grid = cell_centres(size)
    labels = np.full(len(grid), BINS, dtype=np.int64)
    if len(edges):
        gt = nsgraph.adaptive_ground_truth({"nodes_px": nodes, "edges": edges, "lane_tokens": tokens}, grid,
                                           frame="px", max_distance=LANE_RADIUS_PX)
        d = nodes[edges[gt["edge"], 1]] - nodes[edges[gt["edge"], 0]]
        angle = np.arctan2(d[:, 1], d[:, 0]) % (2 * math.pi)
        labels[gt["input"]] = np.floor(angle / (2 * math.pi / BINS)).astype(np.int64) % BINS
    n = size // STRIDE
    return labels.reshape(n, n)


def inputs(batch):
    """(B, 5, H, W) float: LiDAR, RGB, vehicle presence."""
    lidar = batch["lidar"].float().unsqueeze(1) / 255.0
    rgb = batch["rgb"].float() / 255.0
    vehicle = (batch["vehicle"] >= 0).float().unsqueeze(1)
    return torch.cat([lidar, rgb, vehicle], dim=1)


def make_net():
    return nn.Sequential(
        nn.Conv2d(5, 16, 3, padding=1), nn.ReLU(), nn.MaxPool2d(2),
        nn.Conv2d(16, 32, 3, padding=1), nn.ReLU(), nn.MaxPool2d(2),
        nn.Conv2d(32, 32, 3, padding=1), nn.ReLU(),
        nn.Conv2d(32, BINS + 1, 1))


def graph_from_directions(classes):
    """Nodes at lane cells; an edge from each to the cell its direction points at, when
    that one is a lane cell too."""
    n = classes.shape[0]
    index = -np.ones((n, n), dtype=np.int64)
    rows, cols = np.nonzero(classes < BINS)
    index[rows, cols] = np.arange(len(rows))
    nodes = np.stack([cols * STRIDE + STRIDE / 2 - 0.5, rows * STRIDE + STRIDE / 2 - 0.5], axis=1).astype(float)
    edges = []
    for k, (r, c) in enumerate(zip(rows, cols)):
        angle = (classes[r, c] + 0.5) * 2 * math.pi / BINS
        r2, c2 = r + int(round(math.sin(angle))), c + int(round(math.cos(angle)))
        if 0 <= r2 < n and 0 <= c2 < n and index[r2, c2] >= 0 and index[r2, c2] != k:
            edges.append((k, int(index[r2, c2])))
    return nodes.reshape(-1, 2), np.array(edges, dtype=np.int64).reshape(-1, 2)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--dataset", required=True)
    p.add_argument("--steps", type=int, default=50)
    p.add_argument("--batch-size", type=int, default=4)
    p.add_argument("--max-tiles", type=int, default=0, help="use at most this many tiles per split (0 = all)")
    p.add_argument("--workers", type=int, default=0)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--out", default="lanedir-out")
    a = p.parse_args(argv)
    torch.manual_seed(a.seed)
    os.makedirs(a.out, exist_ok=True)

    modalities = ("lidar", "rgb", "vehicle")
    train = ntorch.TorchDataset(a.dataset, "train", modalities=modalities, seed=a.seed,
                                augment=ntorch.Augment(dropout={"rgb": 0.2}, brightness=0.1, contrast=0.1,
                                                       flips=True, rot90=True))
    if a.max_tiles:
        train = torch.utils.data.Subset(train, range(min(a.max_tiles, len(train))))
    loader = torch.utils.data.DataLoader(train, batch_size=a.batch_size, shuffle=True, num_workers=a.workers,
                                         collate_fn=ntorch.collate, drop_last=False)
    net = make_net()
    opt = torch.optim.Adam(net.parameters(), lr=3e-3)
    weights = torch.ones(BINS + 1)
    weights[BINS] = 0.2  # background dominates
    loss_fn = nn.CrossEntropyLoss(weight=weights)
    step, epoch = 0, 0
    while step < a.steps:
        base = train.dataset if isinstance(train, torch.utils.data.Subset) else train
        base.set_epoch(epoch)
        for batch in loader:
            size = batch["lidar"].shape[-1]
            labels = []
            for b in range(len(batch["key"])):
                sel = batch["node_batch"] == b
                offset = int(batch["num_nodes"][:b].sum())
                edges = batch["edges"][batch["node_batch"][batch["edges"][:, 0]] == b] - offset
                labels.append(direction_labels(batch["nodes"][sel].double().numpy(), edges.numpy(),
                                               batch["lane_tokens"][b], size))
            loss = loss_fn(net(inputs(batch)), torch.from_numpy(np.stack(labels)))
            opt.zero_grad()
            loss.backward()
            opt.step()
            step += 1
            print(f"step {step}: loss {loss.item():.4f}", flush=True)
            if step >= a.steps:
                break
        epoch += 1

    test = nsgraph.Dataset(a.dataset, "test", modalities=modalities)
    n_test = min(a.max_tiles, len(test)) if a.max_tiles else len(test)
    predictions = {}
    net.eval()
    with torch.no_grad():
        for i in range(n_test):
            sample = ntorch.to_tensors(test[i])
            batch = ntorch.collate([sample])
            classes = net(inputs(batch)).argmax(dim=1)[0].numpy()
            predictions[sample["key"]] = graph_from_directions(classes)
    submission = nsgraph.write_submission(os.path.join(a.out, "submission.json"), predictions)
    report = nsgraph.score(a.dataset, submission, split="test")
    with open(os.path.join(a.out, "report.json"), "w") as f:
        json.dump(report, f, indent=1)
    mean = report["aggregate"]["mean"]
    fmt = lambda x: "undefined" if x is None else f"{x:.3f}"
    print(f"scored {report['aggregate']['n_tiles']} test tiles ({n_test} predicted): APLS {fmt(mean['apls'])}, "
          f"F1 {fmt(mean['f1'])}, direction accuracy {fmt(mean['direction_accuracy'])}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

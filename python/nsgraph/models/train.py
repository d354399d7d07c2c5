"""Trains LaneGraphNet on a dataset `nsgraph generate` wrote.

    /usr/bin/python3 -m nsgraph.models.train --dataset D --split train --out run/ [--epochs N]

Seeded and repeatable: the same seed, data and thread count give the same weights on the
same machine (torch.manual_seed, deterministic algorithms, a fixed thread count, data
order and augmentations drawn from the seed). Writes run/checkpoint.pt after every epoch
(temp file + rename) and run/model.pt at the end; --resume continues from the checkpoint.
"""
import argparse
import json
import os
import sys
import time

import numpy as np
import torch
from torch.nn import functional as F

from .. import _nsgraph
from ..torch import Augment, TorchDataset
from . import labels as L
from .lanegraphnet import (DIRECTION_CLASSES, STRIDE, TILE_MULTIPLE, LaneGraphNet, PairHead, encode_inputs,
                           pair_inputs)

PAIR_RADIUS_PX = _nsgraph.net_graph_options()["pair_radius_px"]


class NetDataset(TorchDataset):
    """nsgraph.torch's dataset and augmentations, yielding the network's inputs and labels."""

    def __getitem__(self, i):
        tile = self.tiles[i]
        if self.augment is not None:
            self.augment(tile, np.random.default_rng([self.seed, self.epoch, int(i)]))
        size = tile["coverage"].shape[0]
        if size % TILE_MULTIPLE or tile["coverage"].shape[1] != size:
            raise ValueError(f"tile {tile['key']}: LaneGraphNet needs square tiles whose side is a multiple of "
                             f"{TILE_MULTIPLE} px, got {tile['coverage'].shape}")
        graph = {k: tile["graph"][k] for k in ("nodes_px", "edges", "lane_tokens")}
        heat, offset, mask = L.anchor_targets(graph["nodes_px"], size)
        jitter_rng = np.random.default_rng([self.seed, self.epoch, int(i), 1])
        anchors = L.jittered_nodes(graph["nodes_px"], size, jitter_rng)
        pairs = L.candidate_pairs(anchors, PAIR_RADIUS_PX)
        return {"inputs": {k: torch.from_numpy(v) for k, v in encode_inputs(tile).items()},
                "heat": torch.from_numpy(heat), "offset": torch.from_numpy(offset), "mask": torch.from_numpy(mask),
                "direction": torch.from_numpy(L.direction_targets(graph, size)),
                "anchors": anchors, "pairs": pairs, "pair_labels": L.connection_labels(graph, anchors, pairs),
                "graph": graph, "size": size}


def collate(samples):
    batch = {"inputs": {k: torch.stack([s["inputs"][k] for s in samples]) for k in samples[0]["inputs"]}}
    for k in ("heat", "offset", "mask", "direction"):
        batch[k] = torch.stack([s[k] for s in samples])
    for k in ("anchors", "pairs", "pair_labels", "graph", "size"):
        batch[k] = [s[k] for s in samples]
    return batch


def focal_loss(logit, target, mask):
    """CenterNet's penalty-reduced focal loss on the anchor heatmap."""
    p = torch.sigmoid(logit).clamp(1e-4, 1 - 1e-4)
    pos = mask.float()
    pos_loss = -torch.log(p) * (1 - p) ** 2 * pos
    neg_loss = -torch.log(1 - p) * p ** 2 * (1 - target) ** 4 * (1 - pos)
    return (pos_loss.sum() + neg_loss.sum()) / pos.sum().clamp(min=1.0)


def own_anchor_pairs(heat_logit, offset, direction_logit, batch, b):
    """The network's current anchors on tile b (as net_anchors decodes them) with their
    adaptive-ground-truth labels, so the relationship head also sees what it gets at test."""
    with torch.no_grad():
        heat = torch.sigmoid(heat_logit[b, 0]).numpy()
        prob = torch.softmax(direction_logit[b], 0).numpy()
        a = _nsgraph.net_anchors(heat, offset[b].numpy(), prob, batch["size"][b])
    return a["points"], a["pairs"], L.connection_labels(batch["graph"][b], a["points"], a["pairs"])


def losses(net, head, batch, use_own_anchors):
    heat_logit, offset, direction_logit, feats = net(**batch["inputs"])
    mask = batch["mask"]
    out = {"heat": focal_loss(heat_logit[:, 0], batch["heat"], mask)}
    m = mask.unsqueeze(1).expand_as(offset)
    out["offset"] = (F.l1_loss(offset[m], batch["offset"][m], reduction="sum") / mask.sum().clamp(min=1))
    weights = torch.ones(DIRECTION_CLASSES)
    weights[L.BACKGROUND] = 0.2
    out["direction"] = F.cross_entropy(direction_logit, batch["direction"], weight=weights)
    xs, ys = [], []
    for b in range(len(batch["pairs"])):
        sets = [(batch["anchors"][b], batch["pairs"][b], batch["pair_labels"][b])]
        if use_own_anchors:
            sets.append(own_anchor_pairs(heat_logit.detach(), offset.detach(), direction_logit.detach(), batch, b))
        for points, pairs, y in sets:
            if len(pairs):
                xs.append(pair_inputs(feats[b], points, pairs, PAIR_RADIUS_PX))
                ys.append(torch.from_numpy(np.asarray(y, np.float32)))
    if xs:
        x, y = torch.cat(xs), torch.cat(ys)
        pos = y.sum().clamp(min=1.0)
        out["pairs"] = F.binary_cross_entropy_with_logits(head(x)[:, 0], y, pos_weight=(len(y) - pos) / pos)
    else:
        out["pairs"] = heat_logit.sum() * 0.0
    return out


class ProgressBar:
    """One line on stderr: epoch, step, losses, elapsed and remaining time."""

    def __init__(self, total, enabled=True):
        self.total, self.enabled, self.t0, self.done = total, enabled, time.monotonic(), 0

    def update(self, epoch, values):
        self.done += 1
        if not self.enabled:
            return
        s = time.monotonic() - self.t0
        eta = s / self.done * (self.total - self.done)
        text = " ".join(f"{k} {v:.3f}" for k, v in values.items())
        width = 24
        fill = int(width * self.done / self.total)
        sys.stderr.write(f"\rtrain [{'#' * fill}{'.' * (width - fill)}] {self.done}/{self.total} epoch {epoch} "
                         f"{text}  {s:.0f}s, ~{eta:.0f}s left ")
        sys.stderr.flush()

    def close(self):
        if self.enabled:
            sys.stderr.write("\n")


def save(path, state):
    tmp = path + ".tmp"
    torch.save(state, tmp)
    os.replace(tmp, path)


def parse_args(argv=None):
    p = argparse.ArgumentParser(prog="python -m nsgraph.models.train", description=__doc__.split("\n\n")[0])
    p.add_argument("--dataset", required=True, help="dataset folder (manifest.json) from nsgraph generate")
    p.add_argument("--split", default="train")
    p.add_argument("--out", required=True, help="run folder: checkpoint.pt, model.pt, train.json")
    p.add_argument("--epochs", type=int, default=8)
    p.add_argument("--batch-size", type=int, default=4)
    p.add_argument("--lr", type=float, default=3e-3)
    p.add_argument("--max-tiles", type=int, default=0, help="use only the first N tiles (0 = all)")
    p.add_argument("--max-steps", type=int, default=0, help="stop after N steps in total (0 = all epochs)")
    p.add_argument("--own-anchors-from", type=int, default=1,
                   help="epoch from which the relationship head also trains on the network's own anchors")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--threads", type=int, default=2, help="torch threads (fixed: results depend on it)")
    p.add_argument("--resume", action="store_true", help="continue from OUT/checkpoint.pt")
    p.add_argument("--stop-after", type=int, default=0,
                   help="end this run after N epochs (a checkpoint to --resume from; 0 = train to the end)")
    p.add_argument("--no-augment", action="store_true")
    p.add_argument("--quiet", action="store_true")
    a = p.parse_args(argv)
    for name in ("epochs", "batch_size", "threads"):
        if getattr(a, name) < 1:
            p.error(f"--{name.replace('_', '-')}: expected ≥ 1")
    return a


def main(argv=None):
    a = parse_args(argv)
    torch.manual_seed(a.seed)
    torch.use_deterministic_algorithms(True)
    torch.set_num_threads(a.threads)
    os.makedirs(a.out, exist_ok=True)
    augment = None if a.no_augment else Augment(dropout={"rgb": 0.05, "semantic": 0.05, "vehicle": 0.1},
                                                 brightness=0.1, contrast=0.1, flips=True, rot90=True)
    data = NetDataset(a.dataset, a.split, augment=augment, seed=a.seed)
    n = len(data) if a.max_tiles <= 0 else min(a.max_tiles, len(data))
    if n == 0:
        sys.exit(f"{a.dataset}: split '{a.split}' has no tiles")
    net, head = LaneGraphNet(), PairHead()
    params = list(net.parameters()) + list(head.parameters())
    opt = torch.optim.AdamW(params, lr=a.lr, weight_decay=1e-4)
    steps_per_epoch = (n + a.batch_size - 1) // a.batch_size
    total = a.epochs * steps_per_epoch if a.max_steps <= 0 else min(a.max_steps, a.epochs * steps_per_epoch)
    sched = torch.optim.lr_scheduler.OneCycleLR(opt, max_lr=a.lr, total_steps=total, pct_start=0.15)
    ckpt_path = os.path.join(a.out, "checkpoint.pt")
    start_epoch, step, seconds = 0, 0, 0.0
    if a.resume and os.path.exists(ckpt_path):
        c = torch.load(ckpt_path)
        net.load_state_dict(c["net"])
        head.load_state_dict(c["head"])
        opt.load_state_dict(c["optimizer"])
        sched.load_state_dict(c["scheduler"])
        torch.set_rng_state(c["torch_rng"])
        start_epoch, step, seconds = c["epoch"], c["step"], c["seconds"]
    bar = ProgressBar(total - step, enabled=not a.quiet)
    t0 = time.monotonic()
    last_epoch = a.epochs if a.stop_after <= 0 else min(a.epochs, start_epoch + a.stop_after)
    for epoch in range(start_epoch, last_epoch):
        if step >= total:
            break
        data.set_epoch(epoch)
        order = torch.randperm(n, generator=torch.Generator().manual_seed(a.seed * 1000 + epoch)).tolist()
        net.train()
        head.train()
        for s in range(steps_per_epoch):
            if step >= total:
                break
            batch = collate([data[i] for i in order[s * a.batch_size:(s + 1) * a.batch_size]])
            parts = losses(net, head, batch, use_own_anchors=epoch >= a.own_anchors_from)
            loss = parts["heat"] + parts["offset"] + parts["direction"] + parts["pairs"]
            opt.zero_grad()
            loss.backward()
            torch.nn.utils.clip_grad_norm_(params, 5.0)
            opt.step()
            sched.step()
            step += 1
            bar.update(epoch, {k: float(v) for k, v in parts.items()})
        save(ckpt_path, {"net": net.state_dict(), "head": head.state_dict(), "optimizer": opt.state_dict(),
                         "scheduler": sched.state_dict(), "torch_rng": torch.get_rng_state(), "epoch": epoch + 1,
                         "step": step, "seconds": seconds + time.monotonic() - t0})
    bar.close()
    seconds += time.monotonic() - t0
    if last_epoch < a.epochs and step < total:
        if not a.quiet:
            print(f"stopped after epoch {last_epoch} of {a.epochs}: resume with --resume ({ckpt_path})")
        return 0
    size = int(data.tiles[0]["coverage"].shape[0])
    save(os.path.join(a.out, "model.pt"), {"net": net.state_dict(), "head": head.state_dict(), "tile_size_px": size,
                                           "stride_px": STRIDE, "seed": a.seed})
    report = {"dataset": os.path.abspath(a.dataset), "split": a.split, "tiles": n, "epochs": a.epochs, "steps": step,
              "batch_size": a.batch_size, "seed": a.seed, "threads": a.threads, "train_seconds": round(seconds, 1)}
    with open(os.path.join(a.out, "train.json"), "w") as f:
        json.dump(report, f, indent=1)
    if not a.quiet:
        print(f"trained LaneGraphNet on {n} tiles of '{a.split}': {step} steps in {seconds:.0f} s → "
              f"{os.path.join(a.out, 'model.pt')}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

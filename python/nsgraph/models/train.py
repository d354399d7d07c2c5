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

from .cli_help import DefaultsHelpFormatter
from ..progress import Progress
from .. import _nsgraph
from ..dataset import LAYERS
from ..torch import Augment, TorchDataset, _transform
from . import labels as L
from .lanegraphnet import (DIRECTION_CLASSES, STRIDE, TILE_MULTIPLE, LaneGraphNet, PairHead, encode_inputs,
                           pair_inputs)

PAIR_RADIUS_PX = _nsgraph.net_graph_options()["pair_radius_px"]


def mirror_keeping_traffic_side(tile):
    """The tile mirrored east-west with the traffic reversed: a plain mirror image drives on
    the other side of the road (the yellow line moves to the right of the travel
    direction, the road edge to its left), so the edges and the vehicle headings are
    reversed too and the markings keep saying which way the lanes go."""
    _transform(tile, "flip_u")
    graph = dict(tile["graph"])
    graph["edges"] = np.ascontiguousarray(np.asarray(graph["edges"])[:, ::-1])
    tile["graph"] = graph
    if "vehicle" in tile:
        v = tile["vehicle"].copy()
        has = v >= 0
        v[has] = ((v[has].astype(np.float64) + 0.5) % 1.0).astype(np.float32)
        tile["vehicle"] = v
    return tile


def random_crop(tile, crop_px, rng):
    """The tile cut to a random crop_px × crop_px window (rasters and graph coordinates;
    nodes outside the window stay, so lanes crossing its border keep their direction)."""
    h, w = tile["coverage"].shape
    u0, v0 = int(rng.integers(0, w - crop_px + 1)), int(rng.integers(0, h - crop_px + 1))
    for m in LAYERS:
        if m in tile:
            tile[m] = np.ascontiguousarray(tile[m][v0:v0 + crop_px, u0:u0 + crop_px])
    graph = dict(tile["graph"])
    graph["nodes_px"] = np.asarray(graph["nodes_px"], np.float64) - (u0, v0)
    tile["graph"] = graph
    return tile


class NetDataset(TorchDataset):
    """nsgraph.torch's dataset and augmentations, yielding the network's inputs and labels
    (on a random crop_px window of each tile when crop_px is set: cheaper steps, more of
    them — the network is fully convolutional; mirrored with the traffic reversed, half of
    the time, when mirror is set)."""

    crop_px = 0
    mirror = False

    def __getitem__(self, i):
        tile = self.tiles[i]
        if self.augment is not None:
            self.augment(tile, np.random.default_rng([self.seed, self.epoch, int(i)]))
        size = tile["coverage"].shape[0]
        if size % TILE_MULTIPLE or tile["coverage"].shape[1] != size:
            raise ValueError(f"tile {tile['key']}: LaneGraphNet needs square tiles whose side is a multiple of "
                             f"{TILE_MULTIPLE} px, got {tile['coverage'].shape}")
        if self.mirror and np.random.default_rng([self.seed, self.epoch, int(i), 3]).random() < 0.5:
            mirror_keeping_traffic_side(tile)
        if 0 < self.crop_px < size:
            random_crop(tile, self.crop_px, np.random.default_rng([self.seed, self.epoch, int(i), 2]))
            size = self.crop_px
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


def save(path, state):
    tmp = path + ".tmp"
    torch.save(state, tmp)
    os.replace(tmp, path)


def parse_args(argv=None):
    p = argparse.ArgumentParser(prog="python -m nsgraph.models.train", description=__doc__.split("\n\n")[0],
                                formatter_class=DefaultsHelpFormatter)
    p.add_argument("--dataset", required=True, help="dataset folder (manifest.json) from nsgraph generate")
    p.add_argument("--split", default="train", help="the split to train on")
    p.add_argument("--out", required=True, help="run folder: checkpoint.pt, model.pt, train.json")
    p.add_argument("--epochs", type=int, default=60, help="passes over the split")
    p.add_argument("--batch-size", type=int, default=8, help="crops per step")
    p.add_argument("--lr", type=float, default=3e-3, help="Adam learning rate")
    p.add_argument("--crop", type=int, default=128,
                   help="train on random CROP × CROP px windows of the tiles (a multiple of 64; 0 = whole tiles)")
    p.add_argument("--direction-weight", type=float, default=2.0, help="weight of LaneDirNet's loss")
    p.add_argument("--max-tiles", type=int, default=0, help="use only the first N tiles (0 = all)")
    p.add_argument("--max-steps", type=int, default=0, help="stop after N steps in total (0 = all epochs)")
    p.add_argument("--own-anchors-from", type=int, default=1,
                   help="epoch from which the relationship head also trains on the network's own anchors")
    p.add_argument("--seed", type=int, default=1, help="seeds the crops, augmentation and weights")
    p.add_argument("--threads", type=int, default=1,
                   help="torch threads (fixed: results depend on it; 1 is fastest on a shared 2-core machine, "
                        "where OpenMP's spinning barriers waste the other core)")
    p.add_argument("--resume", action="store_true", help="continue from OUT/checkpoint.pt")
    p.add_argument("--stop-after", type=int, default=0,
                   help="end this run after N epochs (a checkpoint to --resume from; 0 = train to the end)")
    p.add_argument("--no-augment", action="store_true", help="no random crops, rotations or mirroring")
    p.add_argument("--flips", action="store_true",
                   help="nsgraph.torch's mirror flips (off: they swap the traffic side, edges kept)")
    p.add_argument("--no-mirror", action="store_true",
                   help="no mirroring with the traffic reversed (on by default, half of the tiles)")
    p.add_argument("--quiet", action="store_true", help="no progress lines")
    a = p.parse_args(argv)
    for name in ("epochs", "batch_size", "threads"):
        if getattr(a, name) < 1:
            p.error(f"--{name.replace('_', '-')}: expected ≥ 1")
    if a.crop < 0 or a.crop % TILE_MULTIPLE:
        p.error(f"--crop {a.crop}: expected 0 or a multiple of {TILE_MULTIPLE}")
    return a


def main(argv=None):
    a = parse_args(argv)
    torch.manual_seed(a.seed)
    torch.use_deterministic_algorithms(True)
    torch.set_num_threads(a.threads)
    torch.set_flush_denormal(True)
    os.makedirs(a.out, exist_ok=True)
    # nsgraph.torch's flips mirror the road but keep the edges' direction: the mirrored road
    # drives on the other side, which teaches LaneDirNet that markings say nothing about
    # direction (--flips, off by default); the trainer's own mirror reverses the traffic too.
    augment = None if a.no_augment else Augment(dropout={"rgb": 0.05, "semantic": 0.05, "vehicle": 0.1},
                                                 brightness=0.1, contrast=0.1, flips=a.flips, rot90=True)
    data = NetDataset(a.dataset, a.split, augment=augment, seed=a.seed)
    data.crop_px = a.crop
    data.mirror = not a.no_augment and not a.no_mirror
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
    # Steps of this run (a resumed run counts from where it starts); losses as the detail.
    bar = Progress("train steps", total - step, enabled=not a.quiet)
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
            loss = parts["heat"] + parts["offset"] + a.direction_weight * parts["direction"] + parts["pairs"]
            opt.zero_grad()
            loss.backward()
            torch.nn.utils.clip_grad_norm_(params, 5.0)
            opt.step()
            sched.step()
            step += 1
            bar.set_detail(f"epoch {epoch} " + " ".join(f"{k} {float(v):.3f}" for k, v in parts.items()))
            bar.advance()
        save(ckpt_path, {"net": net.state_dict(), "head": head.state_dict(), "optimizer": opt.state_dict(),
                         "scheduler": sched.state_dict(), "torch_rng": torch.get_rng_state(), "epoch": epoch + 1,
                         "step": step, "seconds": seconds + time.monotonic() - t0})
    bar.finish()
    seconds += time.monotonic() - t0
    if last_epoch < a.epochs and step < total:
        if not a.quiet:
            print(f"stopped after epoch {last_epoch} of {a.epochs}: resume with --resume ({ckpt_path})")
        return 0
    size = int(data.tiles[0]["coverage"].shape[0])
    save(os.path.join(a.out, "model.pt"), {"net": net.state_dict(), "head": head.state_dict(), "tile_size_px": size,
                                           "stride_px": STRIDE, "seed": a.seed})
    report = {"dataset": os.path.abspath(a.dataset), "split": a.split, "tiles": n, "epochs": a.epochs, "steps": step,
              "batch_size": a.batch_size, "crop_px": a.crop, "direction_weight": a.direction_weight, "lr": a.lr,
              "mirror": data.mirror, "flips": a.flips, "seed": a.seed, "threads": a.threads,
              "train_seconds": round(seconds, 1)}
    with open(os.path.join(a.out, "train.json"), "w") as f:
        json.dump(report, f, indent=1)
    if not a.quiet:
        print(f"trained LaneGraphNet on {n} tiles of '{a.split}': {step} steps in {seconds:.0f} s → "
              f"{os.path.join(a.out, 'model.pt')}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

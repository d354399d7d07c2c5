#!/usr/bin/python3
"""An adversarial scoring case at the per-tile limits of `nsgraph score` (see
docs/scoring-limits.md): a dense connected ground truth (a busy junction: 14 lanes each way
across a 256-px tile crossing at shared nodes, nodes every 2 m = 10 px, 840 nodes) and,
per tile, a prediction that uses every limit in the way that costs the scorer most:

  mesh     one connected grid with diagonals over the whole tile, as large as the
           shortest-path work limit allows (~1 400 nodes, ~2 900 edges): every APLS search
           reaches every node, every node snaps onto the GT
  random   5 000 random nodes (the node limit); long random edges across the tile and short
           ones among 1 000 of them up to the length and work limits
  lanes    the GT's own lanes resampled every 0.5 px up to the node limit (densest
           plausible prediction; GEO/TOPO sample it all)
  copy     the GT itself (a perfect prediction: every APLS search on both graphs covers
           the whole connected junction); must be scored
  copy16   the 16-lane junction against itself (its own ground truth): the
           densest connected copy within the search work limit; must be scored

and, in values.json, a file near the JSON value limit (9.3 M values in 210 tiles of 5 000
nodes and 9 800 edges each, in pieces of 100 nodes; one key the ground truth has, the
other 209 extra, so they are parsed, checked and ignored): what a file at the limits
costs in memory.

mesh and random cost more than the search work limit against the connected junction and
must be refused (exit 1) when they reach it; lanes and both copies must be scored.
and, in refused.json, the mesh at the node and edge limits (5 000 nodes, 10 000 edges),
which the work limit refuses.

usage: make_submission.py OUT_DIR [--nodes N --edges E --length-px L --work W]
writes OUT_DIR/<case>.json (one tile each) and OUT_DIR/gt-<case>.json (its ground truth),
refused.json included.
"""
import argparse
import json
import math
import os
import random

SIZE = 256.0


def gt_junction(lanes=14, spacing_px=10.0):
    """`lanes` one-way lanes each way across the tile (alternating directions), nodes every
    `spacing_px` and at every crossing, shared by the two lanes that cross there: one
    connected graph, as a real junction's lanes and connectors are. 14 lanes (3.7 m apart,
    196 shared crossings: 840 nodes, 1 008 edges) is the busiest plausible connected tile;
    16 lanes (3.2 m) is the densest whose perfect copy is still within the search work limit."""
    offsets = [(k + 0.5) * SIZE / lanes for k in range(lanes)]
    steps = [min(s * spacing_px, SIZE - 0.5) for s in range(int(SIZE // spacing_px) + 1)]
    # Along a lane: the crossings and the regular nodes not within 1 px of one.
    along = sorted(set(offsets) | {t for t in steps if all(abs(t - o) > 1.0 for o in offsets)})
    nodes, index, edges = [], {}, []

    def node(p):
        if p not in index:
            index[p] = len(nodes)
            nodes.append(list(p))
        return index[p]
    for k, offset in enumerate(offsets):
        for horizontal in (True, False):
            ids = [node((t, offset) if horizontal else (offset, t)) for t in along]
            forward = k % 2 == 0
            edges += [[a, b] if forward else [b, a] for a, b in zip(ids, ids[1:])]
    return {"nodes": nodes, "edges": edges}


def path_work(n_nodes, edges):
    """validate::path_search_work: per connected piece nodes x (nodes + 2 x edges)."""
    parent = list(range(n_nodes))

    def root(x):
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x
    for i, j in edges:
        parent[root(i)] = root(j)
    size, arcs = {}, {}
    for k in range(n_nodes):
        size[root(k)] = size.get(root(k), 0) + 1
    for i, _ in edges:
        arcs[root(i)] = arcs.get(root(i), 0) + 2
    return sum(n * (n + arcs.get(r, 0)) for r, n in size.items())


def mesh_within(n_nodes, n_edges, length_px, work):
    """The largest square mesh (plus diagonals) whose path work is within `work`."""
    side = int(math.sqrt(n_nodes))
    while side * side * (side * side + 4 * side * (side - 1)) > work:
        side -= 1
    max_edges = min(n_edges, (work // (side * side) - side * side) // 2)
    return mesh(side * side, max_edges, length_px)


def mesh(n_nodes, n_edges, length_px):
    side = int(math.sqrt(n_nodes))
    step = (SIZE - 1) / (side - 1)
    nodes = [[i * step, j * step] for j in range(side) for i in range(side)]
    edges = []
    for j in range(side):
        for i in range(side):
            k = j * side + i
            if i + 1 < side:
                edges.append([k, k + 1])
            if j + 1 < side:
                edges.append([k, k + side])
    rng = random.Random(1)
    while len(edges) < n_edges:  # diagonals up to the edge limit
        i, j = rng.randrange(side - 1), rng.randrange(side - 1)
        edges.append([j * side + i, (j + 1) * side + i + 1])
    assert len(edges) * step * math.sqrt(2) <= length_px
    return {"nodes": nodes, "edges": edges[:n_edges]}


def random_graph(n_nodes, n_edges, length_px, work, seed=2, linked=1000):
    """n_nodes random nodes; among the first `linked`, long random edges across the tile for
    half the length budget, then short edges within 16-px cells, up to the work limit."""
    rng = random.Random(seed)
    nodes = [[rng.uniform(0, SIZE), rng.uniform(0, SIZE)] for _ in range(n_nodes)]
    cells = {}
    for k in range(linked):
        u, v = nodes[k]
        cells.setdefault((int(u // 16), int(v // 16)), []).append(k)
    max_edges = min(n_edges, ((work - (n_nodes - linked)) // linked - linked) // 2)
    edges, total = [], 0.0
    while total < length_px / 2 and len(edges) < max_edges // 2:
        a, b = rng.randrange(linked), rng.randrange(linked)
        edges.append([a, b])
        total += math.dist(nodes[a], nodes[b])
    while len(edges) < max_edges:
        a = rng.randrange(linked)
        b = rng.choice(cells[(int(nodes[a][0] // 16), int(nodes[a][1] // 16))])
        d = math.dist(nodes[a], nodes[b])
        if total + d > length_px * 0.999:
            break
        edges.append([a, b])
        total += d
    return {"nodes": nodes, "edges": edges}


def dense_lanes(gt, n_nodes, n_edges, length_px, step_px=0.5):
    nodes, edges, total = [], [], 0.0
    for a, b in gt["edges"]:
        pa, pb = gt["nodes"][a], gt["nodes"][b]
        d = math.dist(pa, pb)
        pieces = max(1, int(d / step_px))
        if len(nodes) + pieces + 1 > n_nodes or len(edges) + pieces > n_edges or total + d > length_px:
            break
        first = len(nodes)
        for s in range(pieces + 1):
            t = s / pieces
            nodes.append([pa[0] + t * (pb[0] - pa[0]), pa[1] + t * (pb[1] - pa[1])])
        edges += [[first + s, first + s + 1] for s in range(pieces)]
        total += d
    return {"nodes": nodes, "edges": edges}


def values_file(tiles=210, nodes=5000, piece=100):
    rng = random.Random(3)
    out = {}
    for t in range(tiles):
        edges = []
        for first in range(0, nodes, piece):
            edges += [[k, k + 1] for k in range(first, first + piece - 1)]
            edges += [[k, k + 2] for k in range(first, first + piece - 2)]
        points = []
        for first in range(0, nodes, piece):  # each piece a short straight run
            u, v = rng.randrange(200), rng.randrange(256)
            points += [[u + 0.5 * k, v] for k in range(piece)]
        out[f"values-{t:04d}"] = {"nodes": points, "edges": edges}
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--nodes", type=int, default=5000)
    ap.add_argument("--edges", type=int, default=10000)
    ap.add_argument("--length-px", type=float, default=100000.0)
    ap.add_argument("--work", type=int, default=10_000_000)
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    gt = gt_junction()
    preds = {"mesh": mesh_within(a.nodes, a.edges, a.length_px, a.work),
             "random": random_graph(a.nodes, a.edges, a.length_px, a.work),
             "lanes": dense_lanes(gt, a.nodes, a.edges, a.length_px),
             "copy": gt}
    def dump(name, tiles):
        with open(os.path.join(a.out, name), "w") as f:
            json.dump({"schema_version": "1", "tiles": tiles}, f)
    for k, p in preds.items():
        dump(k + ".json", {k: p})
        dump("gt-" + k + ".json", {k: gt})
    junction16 = gt_junction(16)
    dump("gt-copy16.json", {"copy16": junction16})
    dump("copy16.json", {"copy16": junction16})
    dump("gt-refused.json", {"mesh": gt})
    dump("refused.json", {"mesh": mesh(a.nodes, a.edges, a.length_px)})
    # One key the ground truth has (a short lane), so the file is scored, not refused as
    # predicted for another split; the other 209 are extra.
    dump("gt-values.json", {"values-0000": {"nodes": [[10, 10], [60, 10]], "edges": [[0, 1]]}})
    with open(os.path.join(a.out, "values.json"), "w") as f:
        json.dump({"schema_version": "1", "tiles": values_file()}, f, separators=(",", ":"))
    preds["copy16"] = junction16
    for k, p in preds.items():
        length = sum(math.dist(p["nodes"][i], p["nodes"][j]) for i, j in p["edges"])
        w = path_work(len(p["nodes"]), p["edges"])
        assert w <= a.work and length <= a.length_px, k
        print(f"{k}: {len(p['nodes'])} nodes, {len(p['edges'])} edges, {length:.0f} px, path work {w}")


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""An independent implementation of GEO and TOPO exactly as docs/metrics.md "GEO and TOPO" states
them, written from the text (not from lib/metrics): cleaning, segments, samples, the sample
graphs, the greedy one-to-one matching on the integer key q, and bounded Dijkstra (heapq) for
the TOPO radius. It reproduces the GEO/TOPO values of expected.json (made by the independent
implementation behind the golden set) and is the reference a change of the GEO/TOPO rules
regenerates them with.

usage: geo_topo_reference.py [--rules v2|v3] [--tiles K1,K2,...] [--tolerance 1e-9] [--print] [--write]
  checks GEO and TOPO (values, counts and, for every tile, their aggregate entries) of every
  (or the listed) golden tile against expected.json: --rules v3 (the default) with the rules
  of metrics version 3 (how expected.json's GEO/TOPO values were made, by --write); --rules v2
  with version 2's (they reproduced the file's values before version 3); exit 1
  naming each value that differs by more than the tolerance. --print lists per tile the v2
  and v3 values side by side and which of them change. --write regenerates expected.json's
  GEO/TOPO values, counts and aggregate entries with the v3 rules.
"""
import argparse
import heapq
import json
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
# Rule 2, the number of pieces of a segment of length L: k = max(1, ceil(L/geo_step_px - tol)).
# Version 2 subtracts 1e-9 steps, so a piece of exactly k steps is k pieces but one a hair
# longer (10.00001 px, or any copy moved by 0.001 px) gains a sample; version 3 subtracts
# 0.05 steps, so a segment up to 0.05 steps (0.1 px) over a whole number of steps is not
# split again.
PIECE_TOLERANCE_STEPS_V2 = 1e-9
PIECE_TOLERANCE_STEPS_V3 = 0.05
# Rule 6, the TOPO radius: topo_radius_m / resolution_m + tol px (200 px + 1e-6), so a path
# of exactly 200 px is inside. Unchanged in version 3.
RADIUS_TOLERANCE_PX_V2 = 1e-6
RADIUS_TOLERANCE_PX_V3 = 1e-6
RULES = {"v2": (PIECE_TOLERANCE_STEPS_V2, RADIUS_TOLERANCE_PX_V2),
         "v3": (PIECE_TOLERANCE_STEPS_V3, RADIUS_TOLERANCE_PX_V3)}
# Rule 4: squared distances are quantised to 1e-6 px^2, q = floor(d^2 * 10^6 + 0.5).
QUANTUM_PER_PX2 = 1e6

GEO_KEYS = ["geo_precision", "geo_recall", "geo_f1"]
TOPO_KEYS = [f"topo{d}_{m}" for d in ("", "_directed") for m in ("precision", "recall", "f1")]
METRIC_KEYS = GEO_KEYS + TOPO_KEYS
COUNT_KEYS = ["geo_gt_samples", "geo_pred_samples", "geo_matched", "topo_seeds"]
# aggregate.sums entries that pool GEO (sums of the per-tile counts)
SUM_KEYS = ["geo_gt_samples", "geo_pred_samples", "geo_matched"]


def clean(graph):
    """Self-loops and repeated edges (same direction) dropped, first occurrence kept."""
    seen, edges = set(), []
    for i, j in graph.get("edges", []):
        if i == j or (i, j) in seen:
            continue
        seen.add((i, j))
        edges.append((i, j))
    return [tuple(p) for p in graph.get("nodes", [])], edges


def segments(edges):
    """Rule 1: one segment per node pair joined in either direction: (i, j, fwd, bwd), i < j, sorted."""
    by_pair = {}
    for a, b in edges:
        i, j = min(a, b), max(a, b)
        fwd, bwd = by_pair.get((i, j), (False, False))
        by_pair[(i, j)] = (fwd or a < b, bwd or a > b)
    return [(i, j, f, b) for (i, j), (f, b) in sorted(by_pair.items())]


def sample_graph(graph, step, piece_tol):
    """Rules 2 and 3: the sample positions and the undirected and directed adjacency lists."""
    nodes, edges = clean(graph)
    segs = segments(edges)
    used = sorted({i for i, _, _, _ in segs} | {j for _, j, _, _ in segs})
    index = {n: s for s, n in enumerate(used)}
    pos = [nodes[n] for n in used]
    chains = []
    for i, j, fwd, bwd in segs:
        a, b = nodes[i], nodes[j]
        du, dv = b[0] - a[0], b[1] - a[1]
        length = math.sqrt(du * du + dv * dv)
        k = max(1, math.ceil(length / step - piece_tol))
        chain = [index[i]]
        for s in range(1, k):
            chain.append(len(pos))
            pos.append((a[0] + du * s / k, a[1] + dv * s / k))
        chain.append(index[j])
        chains.append((chain, length / k, fwd, bwd))
    undirected = [[] for _ in pos]
    directed = [[] for _ in pos]
    for chain, w, fwd, bwd in chains:
        for x, y in zip(chain, chain[1:]):
            undirected[x].append((y, w))
            undirected[y].append((x, w))
            if fwd:
                directed[x].append((y, w))
            if bwd:
                directed[y].append((x, w))
    return pos, undirected, directed


def candidates(g_pos, p_pos, match_px):
    """Rule 4's candidate pairs sorted by (q, g, p), as the parallel lists (g, p), through a
    uniform grid of cells a little over match_px wide (every pair within the radius, even one
    whose quantised key rounds onto it, lies in neighbouring cells)."""
    q_max = math.floor(match_px * match_px * QUANTUM_PER_PX2 + 0.5)
    cell = match_px + 0.01
    grid = {}
    for p, (u, v) in enumerate(p_pos):
        grid.setdefault((math.floor(u / cell), math.floor(v / cell)), []).append(p)
    n_g, n_p = len(g_pos), len(p_pos)
    keys = []
    for g, (u, v) in enumerate(g_pos):
        cu, cv = math.floor(u / cell), math.floor(v / cell)
        for nu in (cu - 1, cu, cu + 1):
            for nv in (cv - 1, cv, cv + 1):
                for p in grid.get((nu, nv), ()):
                    du, dv = u - p_pos[p][0], v - p_pos[p][1]
                    q = math.floor((du * du + dv * dv) * QUANTUM_PER_PX2 + 0.5)
                    if q <= q_max:
                        keys.append((q * n_g + g) * n_p + p)  # orders as (q, g, p)
    keys.sort()
    cand_g, cand_p = [], []
    for key in keys:
        gp = key % (n_g * n_p)
        cand_g.append(gp // n_p)
        cand_p.append(gp % n_p)
    return cand_g, cand_p


def greedy(ranks, cand_g, cand_p):
    """Rule 4's scan: the accepted (g, p) of the candidates at these ranks, in rank order."""
    seen_g, seen_p, accepted = set(), set(), []
    for r in ranks:
        g, p = cand_g[r], cand_p[r]
        if g in seen_g or p in seen_p:
            continue
        seen_g.add(g)
        seen_p.add(p)
        accepted.append((g, p))
    return accepted


def reach(adj, src, radius):
    """The samples whose shortest-path distance from src is <= radius (src included)."""
    dist = {src: 0.0}
    heap = [(0.0, src)]
    while heap:
        d, u = heapq.heappop(heap)
        if d > dist[u]:
            continue
        for v, w in adj[u]:
            nd = d + w
            if nd <= radius and nd < dist.get(v, math.inf):
                dist[v] = nd
                heapq.heappush(heap, (nd, v))
    return dist


def ratio(num, den):
    return None if den == 0 else num / den


def f1_of(p, r):
    """Rule 7's F1: undefined if both are, 0 if exactly one is or if P + R = 0."""
    if p is None and r is None:
        return None
    if p is None or r is None or p + r == 0.0:
        return 0.0
    return 2.0 * p * r / (p + r)


def geo_topo(gt, pred, params, rules="v2"):
    """The nine GEO/TOPO values of one tile, keyed as in a report, and their four counts."""
    piece_tol, radius_tol = RULES[rules]
    step, match_px = params["geo_step_px"], params["geo_match_px"]
    radius = params["topo_radius_m"] / params["mpp"] + radius_tol
    g_pos, g_und, g_dir = sample_graph(gt, step, piece_tol)
    p_pos, p_und, p_dir = sample_graph(pred, step, piece_tol)
    n_g, n_p = len(g_pos), len(p_pos)
    cand_g, cand_p = candidates(g_pos, p_pos, match_px)
    seeds = greedy(range(len(cand_g)), cand_g, cand_p)  # increasing q, not g
    m = len(seeds)
    out = {"geo_precision": ratio(m, n_p), "geo_recall": ratio(m, n_g),
           "geo_f1": None if n_g + n_p == 0 else 2.0 * m / (n_g + n_p)}
    by_g = [[] for _ in range(n_g)]  # candidate ranks of each GT sample, increasing
    for r, g in enumerate(cand_g):
        by_g[g].append(r)
    seeds.sort()  # rule 7: summed over seeds in increasing g
    for name, g_adj, p_adj in (("topo", g_und, p_und), ("topo_directed", g_dir, p_dir)):
        sum_p, sum_r = 0.0, 0.0
        for g, p in seeds:
            r_g = reach(g_adj, g, radius)
            r_p = reach(p_adj, p, radius)
            ranks = sorted(r for g2 in r_g for r in by_g[g2] if cand_p[r] in r_p)
            m_s = len(greedy(ranks, cand_g, cand_p))
            sum_p += m_s / len(r_p)
            sum_r += m_s / len(r_g)
        precision, recall = ratio(sum_p, n_p), ratio(sum_r, n_g)
        out[name + "_precision"], out[name + "_recall"] = precision, recall
        out[name + "_f1"] = f1_of(precision, recall)
    out["counts"] = {"geo_gt_samples": n_g, "geo_pred_samples": n_p, "geo_matched": m,
                     "topo_seeds": len(seeds)}
    return out


def compute(gt, pred, params, keys, rules):
    return {key: geo_topo(gt[key], pred.get(key, {"nodes": [], "edges": []}), params, rules) for key in keys}


def aggregate(got, metric_keys=METRIC_KEYS, sum_keys=SUM_KEYS, pooled=True):
    """The GEO/TOPO entries of aggregate (mean, n_defined, n_undefined, pooled, sums) of
    per-tile values, tiles in key order as the scorer sums (other metrics' entries with
    their keys; pooled=False leaves out GEO's pooled figures)."""
    agg = {"mean": {}, "n_defined": {}, "n_undefined": {}, "sums": {}}
    keys = sorted(got)
    for k in metric_keys:
        defined = [got[key][k] for key in keys if got[key][k] is not None]
        total = 0.0
        for v in defined:
            total += v
        agg["mean"][k] = total / len(defined) if defined else None
        agg["n_defined"][k] = len(defined)
        agg["n_undefined"][k] = len(keys) - len(defined)
    for c in sum_keys:
        agg["sums"][c] = sum(got[key]["counts"][c] for key in keys)
    if not pooled:
        return agg
    m, n_g, n_p = (agg["sums"][c] for c in ("geo_matched", "geo_gt_samples", "geo_pred_samples"))
    agg["pooled"] = {"geo_precision": ratio(m, n_p), "geo_recall": ratio(m, n_g),
                     "geo_f1": None if n_g + n_p == 0 else 2.0 * m / (n_g + n_p)}
    return agg


def differs(w, v, tolerance):
    if isinstance(w, int) and isinstance(v, int):
        return w != v
    return (w is None) != (v is None) or (w is not None and abs(w - v) > tolerance * max(1.0, abs(w)))


def compare(got, want_tiles, want_agg, tolerance):
    bad = 0
    for key, values in got.items():
        want = want_tiles[key]
        for k in METRIC_KEYS:
            if differs(want[k], values[k], tolerance):
                print(f"{key}.{k}: expected {want[k]}, got {values[k]}")
                bad += 1
        for c in COUNT_KEYS:
            if want["counts"][c] != values["counts"][c]:
                print(f"{key}.{c}: expected {want['counts'][c]}, got {values['counts'][c]}")
                bad += 1
    if want_agg is not None:
        for group, entries in aggregate(got).items():
            for k, v in entries.items():
                w = want_agg[group][k]
                if differs(w, v, tolerance):
                    print(f"aggregate.{group}.{k}: expected {w}, got {v}")
                    bad += 1
    return bad


def write_expected(expected, got, path):
    """expected.json with every tile's GEO/TOPO values and counts and their aggregate entries
    replaced (every other metric, count and aggregate entry is not touched)."""
    assert sorted(got) == sorted(expected["tiles"])
    for key, values in got.items():
        for k in METRIC_KEYS:
            expected["tiles"][key][k] = values[k]
        for c in COUNT_KEYS:
            expected["tiles"][key]["counts"][c] = values["counts"][c]
    for group, entries in aggregate(got).items():
        for k, v in entries.items():
            assert k in expected["aggregate"][group], f"aggregate.{group}.{k}"
            expected["aggregate"][group][k] = v
    if "topo_seeds" in expected["aggregate"]["sums"]:
        expected["aggregate"]["sums"]["topo_seeds"] = sum(v["counts"]["topo_seeds"] for v in got.values())
    # Version 4 added the map-change metrics and left every GEO/TOPO rule of version 3 as it was.
    expected["metrics_version"] = "4"
    expected["params"]["tol_ceil"] = PIECE_TOLERANCE_STEPS_V3  # the file's record of rule 2's tolerance
    expected["params"]["tol_radius_px"] = RADIUS_TOLERANCE_PX_V3
    note = "; GEO/TOPO regenerated for metrics version 3 by geo_topo_reference.py --write"
    if not expected["about"].endswith(note):
        expected["about"] += note
    with open(path, "w") as f:
        json.dump(expected, f, indent=1, sort_keys=True)
        f.write("\n")


def fmt(v):
    return "null" if v is None else f"{v:.9f}" if isinstance(v, float) else str(v)


def print_side_by_side(v2, v3):
    """Per tile, every GEO/TOPO value and count under v2 and v3 (* where they differ), the
    aggregate entries, and a summary: per changed tile the largest change of a value and the
    changes of the counts."""
    names = METRIC_KEYS + COUNT_KEYS
    print(f"{'tile':28} {'value':26} {'v2':>14} {'v3':>14} {'v3 - v2':>12}")
    summary, worst = [], (0.0, "")
    for key in sorted(v2):
        big, counts = (0.0, ""), []
        for k in names:
            a = v2[key][k] if k in METRIC_KEYS else v2[key]["counts"][k]
            b = v3[key][k] if k in METRIC_KEYS else v3[key]["counts"][k]
            d = "" if a is None or b is None else (f"{b - a:+.3e}" if k in METRIC_KEYS else f"{b - a:+d}")
            print(f"{key:28} {k:26} {fmt(a):>14} {fmt(b):>14} {d:>12}{'' if a == b else ' *'}")
            if a == b:
                continue
            if k in COUNT_KEYS:
                counts.append(f"{k} {a} -> {b}")
            elif a is None or b is None:
                big = (math.inf, k)
            elif abs(b - a) > big[0]:
                big = (abs(b - a), k)
        if big[1] or counts:
            summary.append((key, big, counts))
            if big[0] > worst[0]:
                worst = (big[0], f"{key}.{big[1]}")
    print()
    agg2, agg3 = aggregate(v2), aggregate(v3)
    for group in ("mean", "pooled", "sums"):
        for k in agg2[group]:
            a, b = agg2[group][k], agg3[group][k]
            d = "" if a is None or b is None else (f"{b - a:+.3e}" if isinstance(a, float) else f"{b - a:+d}")
            print(f"{'aggregate.' + group:28} {k:26} {fmt(a):>14} {fmt(b):>14} {d:>12}{'' if a == b else ' *'}")
    print()
    n_values = sum(1 for _, big, _ in summary if big[1])
    print(f"v2 -> v3: {len(summary)} of {len(v2)} tiles change a GEO/TOPO count, {n_values} a value:")
    for key, big, counts in summary:
        value = f"max |change| {big[0]:.3g} ({big[1]})" if big[1] else "values unchanged"
        print(f"  {key}: {value}; {', '.join(counts)}")
    if worst[1]:
        print(f"largest change of a value: {worst[0]:.6g} ({worst[1]})")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tiles", default="", help="comma-separated tile keys (default: every tile)")
    ap.add_argument("--tolerance", type=float, default=1e-9)
    ap.add_argument("--rules", choices=("v2", "v3"), default="v3",
                    help="v3 (default): metrics version 3's rule 2 and 6 tolerances (expected.json's); v2: version 2's")
    ap.add_argument("--print", dest="print_", action="store_true",
                    help="print per tile the v2 and v3 values side by side")
    ap.add_argument("--write", action="store_true", help="rewrite expected.json's GEO/TOPO values with the v3 rules")
    a = ap.parse_args()
    with open(os.path.join(HERE, "gt.json")) as f:
        gt = json.load(f)["tiles"]
    with open(os.path.join(HERE, "pred.json")) as f:
        pred = json.load(f)["tiles"]
    with open(os.path.join(HERE, "expected.json")) as f:
        expected = json.load(f)
    keys = a.tiles.split(",") if a.tiles else sorted(gt)
    params = expected["params"]
    if a.write:
        assert not a.tiles, "--write recomputes every tile with the v3 rules"
        got = compute(gt, pred, params, keys, "v3")
        write_expected(expected, got, os.path.join(HERE, "expected.json"))
        print(f"expected.json: GEO/TOPO values of {len(keys)} tiles rewritten with the v3 rules")
        return 0
    if a.print_:
        print_side_by_side(compute(gt, pred, params, keys, "v2"), compute(gt, pred, params, keys, "v3"))
        return 0
    got = compute(gt, pred, params, keys, a.rules)
    bad = compare(got, expected["tiles"], None if a.tiles else expected["aggregate"], a.tolerance)
    print(f"{len(keys)} tiles, rules {a.rules}: {bad} GEO/TOPO values differ by more than {a.tolerance}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())

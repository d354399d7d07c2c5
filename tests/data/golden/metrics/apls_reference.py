#!/usr/bin/python3
"""An independent implementation of the APLS family exactly as docs/metrics.md "APLS" states
it, written from the text (not from lib/metrics): brute-force snapping onto every segment,
the split graph B', Dijkstra with heapq. It reproduces the APLS values of expected.json
(made by the independent implementation behind the golden set) and is the reference a
change of the APLS rules regenerates them with.

usage: apls_reference.py [--rules v1|v2] [--tiles K1,K2,...] [--tolerance 1e-9] [--write]
  checks the APLS family of every (or the listed) golden tile: --rules v1 against
  expected_apls_v1.json (the golden set's version-1 numbers, made by the independent
  implementation behind it), v2 (the default) against expected.json; exit 1 naming each
  value that differs by more than the tolerance. --write regenerates expected.json's APLS
  values and means with the v2 rules (how they were made).
"""
import argparse
import heapq
import json
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
# Rule 3, the points of a segment that are one point: metrics version 1 compared the
# projections' t (within 1e-12); version 2 compares distances along the segment (within
# 0.01 m), so a control point a centimetre off a junction node is that node.
SAME_SPOT_T_V1 = 1e-12
SAME_SPOT_M_V2 = 0.01


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
    """One segment per node pair joined in either direction: (i, j, fwd, bwd), i < j, sorted."""
    by_pair = {}
    for a, b in edges:
        i, j = min(a, b), max(a, b)
        fwd, bwd = by_pair.get((i, j), (False, False))
        by_pair[(i, j)] = (fwd or a < b, bwd or a > b)
    return [(i, j, f, b) for (i, j), (f, b) in sorted(by_pair.items())]


def project(p, a, b):
    """(distance, t) of point p to segment ab, t clamped to [0, 1]."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    len2 = dx * dx + dy * dy
    t = 0.0
    if len2 > 0.0:
        t = min(1.0, max(0.0, ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2))
    qx, qy = a[0] + t * dx - p[0], a[1] + t * dy - p[1]
    return math.sqrt(qx * qx + qy * qy), t


def adjacency(n, arcs):
    adj = [[] for _ in range(n)]
    for u, v, w in arcs:
        adj[u].append((v, w))
    return adj


def dijkstra(adj, src):
    dist = {src: 0.0}
    heap = [(0.0, src)]
    while heap:
        d, u = heapq.heappop(heap)
        if d > dist[u]:
            continue
        for v, w in adj[u]:
            nd = d + w
            if nd < dist.get(v, math.inf):
                dist[v] = nd
                heapq.heappush(heap, (nd, v))
    return dist


def arcs_of(nodes, segs, directed):
    arcs = []
    for i, j, fwd, bwd in segs:
        w = math.dist(nodes[i], nodes[j])
        if not directed or fwd:
            arcs.append((i, j, w))
        if not directed or bwd:
            arcs.append((j, i, w))
    return arcs


def split_graph(b_nodes, b_segs, snaps, snap_m, directed, rules):
    """B' (node count, arcs) and the B' node of every control point (None: unmatched)."""
    node_of = [None] * len(snaps)
    on_seg = {}
    for a, (seg, d, t) in enumerate(snaps):
        if seg is not None and d <= snap_m:
            on_seg.setdefault(seg, []).append((t, a))
    nxt = len(b_nodes)
    arcs = []
    for k, (i, j, fwd, bwd) in enumerate(b_segs):
        pa, pb = b_nodes[i], b_nodes[j]
        length = math.dist(pa, pb)
        chain = [(i, pa, 0.0)]  # (node, position, where along the segment: t or metres)
        last = 0.0
        for t, a in sorted(on_seg.get(k, [])):
            if rules == "v1":
                at, tol, shared = t, SAME_SPOT_T_V1, t - last
                at_start, at_end = t <= tol, t >= 1.0 - tol
            else:
                at, to_end, tol = t * length, (1.0 - t) * length, SAME_SPOT_M_V2
                at_start, at_end = at <= tol and at <= to_end, to_end <= tol
                shared = at - chain[-1][2]
            if at_start:
                node_of[a] = i
            elif at_end:
                node_of[a] = j
            else:
                if len(chain) == 1 or shared > tol:
                    chain.append((nxt, (pa[0] + t * (pb[0] - pa[0]), pa[1] + t * (pb[1] - pa[1])), at))
                    nxt += 1
                last = t
                node_of[a] = chain[-1][0]
        chain.append((j, pb, None))
        for (u, pu, _), (v, pv, _) in zip(chain, chain[1:]):
            w = math.dist(pu, pv)
            if not directed or fwd:
                arcs.append((u, v, w))
            if not directed or bwd:
                arcs.append((v, u, w))
    return nxt, arcs, node_of


def one_sided(a_nodes, a_segs, b_nodes, b_segs, snap_m, directed, min_path_m, rules):
    """(pairs, cost sum) of C(A -> B) before 1 - mean (rules 1-5)."""
    snaps = []
    for p in a_nodes:  # rule 2: the nearest segment, ties to the smallest (i, j)
        best = (None, math.inf, 0.0)
        for k, (i, j, _, _) in enumerate(b_segs):
            d, t = project(p, b_nodes[i], b_nodes[j])
            if d < best[1]:
                best = (k, d, t)
        snaps.append(best)
    n_b, b_arcs, node_of = split_graph(b_nodes, b_segs, snaps, snap_m, directed, rules)
    a_adj = adjacency(len(a_nodes), arcs_of(a_nodes, a_segs, directed))
    b_adj = adjacency(n_b, b_arcs)
    pairs, cost = 0, 0.0
    for a in range(len(a_nodes)):
        la_of = dijkstra(a_adj, a)
        lb_of = None
        for b in sorted(la_of):
            la = la_of[b]
            if b == a or la < min_path_m:
                continue
            pairs += 1
            if node_of[a] is None or node_of[b] is None:
                cost += 1.0
                continue
            if lb_of is None:
                lb_of = dijkstra(b_adj, node_of[a])
            lb = lb_of.get(node_of[b], math.inf)
            cost += 1.0 if lb == math.inf else min(1.0, abs(la - lb) / la)
    return pairs, cost


def side_value(pairs, cost):
    return None if pairs == 0 else 1.0 - cost / pairs


def combine(gp, pg):
    c1, c2 = side_value(*gp), side_value(*pg)
    if c1 is None:
        apls = None
    elif c2 is None or c1 <= 0.0 or c2 <= 0.0:
        apls = 0.0
    else:
        apls = 2.0 * c1 * c2 / (c1 + c2)
    return apls, c1, c2


def apls_family(gt, pred, params, rules="v2"):
    """The nine APLS values of one tile, keyed as in a report, and the two pair counts."""
    res = params["mpp"]  # expected.json's parameter names (the golden set's own)
    g_nodes, g_edges = clean(gt)
    p_nodes, p_edges = clean(pred)
    g_m = [(u * res, v * res) for u, v in g_nodes]
    p_m = [(u * res, v * res) for u, v in p_nodes]
    g_segs, p_segs = segments(g_edges), segments(p_edges)
    out = {}
    for name, snap_m, directed in (("apls", params["snap_m"], False),
                                   ("apls_directed", params["snap_m"], True),
                                   ("apls_strict", params["strict_snap_m"], False)):
        gp = one_sided(g_m, g_segs, p_m, p_segs, snap_m, directed, params["min_path_m"], rules)
        pg = one_sided(p_m, p_segs, g_m, g_segs, snap_m, directed, params["min_path_m"], rules)
        out[name], out[name + "_gt_to_pred"], out[name + "_pred_to_gt"] = combine(gp, pg)
        if name == "apls":
            out["counts"] = {"apls_gt_pairs": gp[0], "apls_pred_pairs": pg[0]}
    return out


APLS_KEYS = [f"{name}{side}" for name in ("apls", "apls_directed", "apls_strict")
             for side in ("", "_gt_to_pred", "_pred_to_gt")]


def compute(gt, pred, params, keys, rules):
    return {key: apls_family(gt[key], pred.get(key, {"nodes": [], "edges": []}), params, rules) for key in keys}


def compare(got, want_tiles, tolerance):
    bad = 0
    for key, values in got.items():
        want = want_tiles[key]
        for k, v in values.items():
            if k == "counts":
                for c, n in v.items():
                    if want["counts"][c] != n:
                        print(f"{key}.{c}: expected {want['counts'][c]}, got {n}")
                        bad += 1
                continue
            w = want[k]
            if (w is None) != (v is None) or (w is not None and abs(w - v) > tolerance * max(1.0, abs(w))):
                print(f"{key}.{k}: expected {w}, got {v}")
                bad += 1
    return bad


def write_expected(expected, got, path):
    """expected.json with the APLS family of every tile and their aggregate means replaced
    (the other metrics and every count but the APLS pair counts are not touched)."""
    for key, values in got.items():
        for k in APLS_KEYS:
            expected["tiles"][key][k] = values[k]
    mean = expected["aggregate"]["mean"]
    for k in APLS_KEYS:
        defined = [expected["tiles"][key][k] for key in sorted(expected["tiles"]) if expected["tiles"][key][k] is not None]
        total = 0.0
        for v in defined:  # in key order, as the scorer sums
            total += v
        mean[k] = total / len(defined) if defined else None
        assert len(defined) == expected["aggregate"]["n_defined"][k], k
    # Version 3 changed GEO only: the APLS rules of version 2 hold in every later version.
    if int(expected["metrics_version"]) < 2:
        expected["metrics_version"] = "2"
    note = "; APLS family regenerated for metrics version 2 by apls_reference.py --write"
    if not expected["about"].endswith(note):
        expected["about"] += note
    with open(path, "w") as f:
        json.dump(expected, f, indent=1, sort_keys=True)
        f.write("\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tiles", default="", help="comma-separated tile keys (default: every tile)")
    ap.add_argument("--tolerance", type=float, default=1e-9)
    ap.add_argument("--rules", choices=("v1", "v2"), default="v2",
                    help="v1: check expected_apls_v1.json (the golden set's own numbers); v2: expected.json")
    ap.add_argument("--write", action="store_true", help="rewrite expected.json's APLS values with the v2 rules")
    a = ap.parse_args()
    with open(os.path.join(HERE, "gt.json")) as f:
        gt = json.load(f)["tiles"]
    with open(os.path.join(HERE, "pred.json")) as f:
        pred = json.load(f)["tiles"]
    with open(os.path.join(HERE, "expected.json")) as f:
        expected = json.load(f)
    keys = a.tiles.split(",") if a.tiles else sorted(gt)
    got = compute(gt, pred, expected["params"], keys, a.rules)
    if a.write:
        assert a.rules == "v2" and not a.tiles, "--write recomputes every tile with the v2 rules"
        write_expected(expected, got, os.path.join(HERE, "expected.json"))
        print(f"expected.json: APLS values of {len(keys)} tiles rewritten with the v2 rules")
        return 0
    if a.rules == "v1":
        with open(os.path.join(HERE, "expected_apls_v1.json")) as f:
            want_tiles = json.load(f)["tiles"]
    else:
        want_tiles = expected["tiles"]
    bad = compare(got, want_tiles, a.tolerance)
    print(f"{len(keys)} tiles, rules {a.rules}: {bad} APLS values differ by more than {a.tolerance}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())

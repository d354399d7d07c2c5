#!/usr/bin/python3
"""An independent computation of metrics v4's map-change metrics, written from docs/metrics.md
"Map change" (not from lib/metrics): the GEO samples of the current map, its prior and the
prediction (geo_topo_reference.py's rules 1-2, with each sample's edge labels), the coverage
test "some sample of the other set within geo_match_px" by brute force over every pair with
rule 4's integer key, and the changed/unchanged GEO and TOPO recalls with
geo_topo_reference.py's matching and a brute-force TOPO per seed.

The cases are hand-made tiles of the kinds a map update holds — a lane added, removed, moved,
retyped, a turn connector added between kept lanes — each scored against a prediction that
follows the current map, one that copies the prior, and ones in between. Edge labels are
EdgeFlag bytes: 4 unchanged, 8 added, 16 removed (prior edges only), 32 moved, 64 retyped.

usage: change_reference.py [--write]
  checks change_cases.json (exit 1 naming each value that differs by more than 1e-9 or each
  count that differs); --write writes it.
"""
import argparse
import json
import math
import os
import sys

import geo_topo_reference as ref

HERE = os.path.dirname(os.path.abspath(__file__))
CASES_FILE = os.path.join(HERE, "change_cases.json")
PARAMS = {"geo_step_px": 2.0, "geo_match_px": 8.0, "topo_radius_m": 40.0, "mpp": 0.2}
UNCHANGED, ADDED, REMOVED, MOVED, RETYPED = 4, 8, 16, 32, 64
CHANGED_BITS = ADDED | REMOVED | MOVED | RETYPED


def lane(points, step=10.0):
    """A polyline as a chain of nodes at most `step` px apart (a lane resampled at 2 m)."""
    nodes = [tuple(points[0])]
    for (u0, v0), (u1, v1) in zip(points, points[1:]):
        n = max(1, math.ceil(math.hypot(u1 - u0, v1 - v0) / step))
        nodes += [(u0 + (u1 - u0) * s / n, v0 + (v1 - v0) * s / n) for s in range(1, n + 1)]
    return nodes


def graph(*lanes):
    """{nodes, edges, edge_flags} from (polyline nodes, flag) pairs; a lane whose first node
    equals an earlier node (to 1e-9) joins it there, so connectors share their ends."""
    nodes, edges, flags = [], [], []

    def node(p):
        for k, q in enumerate(nodes):
            if abs(q[0] - p[0]) < 1e-9 and abs(q[1] - p[1]) < 1e-9:
                return k
        nodes.append(p)
        return len(nodes) - 1

    for points, flag in lanes:
        ids = [node(p) for p in points]
        for a, b in zip(ids, ids[1:]):
            edges.append([a, b])
            flags.append(flag)
    return {"nodes": [[round(u, 6), round(v, 6)] for u, v in nodes], "edges": edges, "edge_flags": flags}


def samples(g):
    """Rules 1-2's sample positions and each sample's edge labels (the OR over its segments)."""
    piece_tol, _ = ref.RULES["v3"]
    step = PARAMS["geo_step_px"]
    nodes, edges = ref.clean(g)
    raw_flags = g.get("edge_flags") or [0] * len(g["edges"])
    seg_flags, seen = {}, set()
    for k, (i, j) in enumerate(g["edges"]):
        if i == j or (i, j) in seen:
            continue
        seen.add((i, j))
        pair = (min(i, j), max(i, j))
        seg_flags[pair] = seg_flags.get(pair, 0) | raw_flags[k]
    segs = ref.segments(edges)
    used = sorted({i for i, _, _, _ in segs} | {j for _, j, _, _ in segs})
    index = {n: s for s, n in enumerate(used)}
    pos = [tuple(nodes[n]) for n in used]
    bits = [0] * len(pos)
    for i, j, _, _ in segs:
        a, b = nodes[i], nodes[j]
        length = math.hypot(b[0] - a[0], b[1] - a[1])
        k = max(1, math.ceil(length / step - piece_tol))
        f = seg_flags[(i, j)]
        bits[index[i]] |= f
        bits[index[j]] |= f
        for s in range(1, k):
            pos.append((a[0] + (b[0] - a[0]) * s / k, a[1] + (b[1] - a[1]) * s / k))
            bits.append(f)
    return pos, bits


def near(p, others):
    q_max = math.floor(PARAMS["geo_match_px"] ** 2 * ref.QUANTUM_PER_PX2 + 0.5)
    for o in others:
        du, dv = p[0] - o[0], p[1] - o[1]
        if math.floor((du * du + dv * dv) * ref.QUANTUM_PER_PX2 + 0.5) <= q_max:
            return True
    return False


def change_values(gt, prior, pred):
    c, c_bits = samples(gt)
    q, q_bits = samples(prior)
    x, _ = samples(pred)
    counts = {k: 0 for k in COUNT_KEYS}
    change_points = []
    for p, b in zip(c, c_bits):  # the current map where the prior has nothing
        if near(p, q):
            continue
        change_points.append(p)
        hit = near(p, x)
        for kind, bit in (("", None), ("_added", ADDED), ("_moved", MOVED)):
            if bit is None or b & bit:
                counts["change_samples" + kind] += 1
                counts["change_detected" + kind] += hit
    for p, b in zip(q, q_bits):  # the prior where the current map has nothing
        if near(p, c):
            counts["prior_kept_samples"] += 1
            counts["false_changes"] += not near(p, x)
            continue
        change_points.append(p)
        hit = not near(p, x)
        for kind, bit in (("", None), ("_removed", REMOVED), ("_moved", MOVED)):
            if bit is None or b & bit:
                counts["change_samples" + kind] += 1
                counts["change_detected" + kind] += hit
    for p in x:  # claimed additions
        if not near(p, q):
            counts["change_claims"] += 1
            counts["change_claims_true"] += near(p, c)
    for p in q:  # claimed removals
        if not near(p, x):
            counts["change_claims"] += 1
            counts["change_claims_true"] += not near(p, c)
    for p in x:
        if not near(p, change_points):
            counts["unchanged_pred_samples"] += 1
            counts["unchanged_pred_on_map"] += near(p, c)
    for p in c:
        if not near(p, change_points):
            counts["unchanged_gt_samples"] += 1
            counts["unchanged_gt_found"] += near(p, x)
    out = {
        "change_recall": ref.ratio(counts["change_detected"], counts["change_samples"]),
        "change_recall_added": ref.ratio(counts["change_detected_added"], counts["change_samples_added"]),
        "change_recall_removed": ref.ratio(counts["change_detected_removed"], counts["change_samples_removed"]),
        "change_recall_moved": ref.ratio(counts["change_detected_moved"], counts["change_samples_moved"]),
        "change_precision": ref.ratio(counts["change_claims_true"], counts["change_claims"]),
        "false_change_rate": ref.ratio(counts["false_changes"], counts["prior_kept_samples"]),
        "unchanged_precision": ref.ratio(counts["unchanged_pred_on_map"], counts["unchanged_pred_samples"]),
        "unchanged_recall": ref.ratio(counts["unchanged_gt_found"], counts["unchanged_gt_samples"]),
    }
    out["change_f1"] = ref.f1_of(out["change_precision"], out["change_recall"])
    out.update(class_recalls(gt, pred, c, c_bits, x))
    out["counts"] = counts
    return out


def class_recalls(gt, pred, c, c_bits, x):
    """GEO and TOPO recall on the changed (added, moved) and the unchanged (unchanged,
    retyped) edges of the current map: the per-class recalls of docs/metrics.md with these two classes."""
    piece_tol, radius_tol = ref.RULES["v3"]
    g_pos, g_und, _ = ref.sample_graph(gt, PARAMS["geo_step_px"], piece_tol)
    p_pos, p_und, _ = ref.sample_graph(pred, PARAMS["geo_step_px"], piece_tol)
    assert [tuple(p) for p in g_pos] == [tuple(p) for p in c] and len(p_pos) == len(x)
    radius = PARAMS["topo_radius_m"] / PARAMS["mpp"] + radius_tol
    cand_g, cand_p = ref.candidates(g_pos, p_pos, PARAMS["geo_match_px"])
    seeds = sorted(ref.greedy(range(len(cand_g)), cand_g, cand_p))
    by_g = [[] for _ in g_pos]
    for r, g in enumerate(cand_g):
        by_g[g].append(r)
    matched = {g for g, _ in seeds}
    out = {}
    for name in ("changed", "unchanged"):
        # a sample's classes are those of its segments: a node between a changed and an
        # unchanged edge is in both
        in_class = [k for k, b in enumerate(c_bits) if class_of(b, name)]
        n = len(in_class)
        total = 0.0
        for g, p in seeds:
            if class_of(c_bits[g], name):
                r_g = ref.reach(g_und, g, radius)
                r_p = ref.reach(p_und, p, radius)
                ranks = sorted(r for g2 in r_g for r in by_g[g2] if cand_p[r] in r_p)
                total += len(ref.greedy(ranks, cand_g, cand_p)) / len(r_g)
        out[f"geo_recall_{name}"] = ref.ratio(sum(1 for k in in_class if k in matched), n)
        out[f"topo_recall_{name}"] = ref.ratio(total, n)
    return out


def class_of(bits, name):
    """A sample is changed when one of its segments is a centreline the prior did not have
    (added, moved), unchanged when one is the same centreline (unchanged, retyped: a new
    divider, the same lane); a node between the two is in both. Per segment the labels are
    one edge's, or those of its two directions."""
    if name == "changed":
        return bool(bits & (ADDED | MOVED | REMOVED))
    return bool(bits & (UNCHANGED | RETYPED))


COUNT_KEYS = ["change_samples", "change_detected", "change_samples_added", "change_detected_added",
              "change_samples_removed", "change_detected_removed", "change_samples_moved", "change_detected_moved",
              "change_claims", "change_claims_true", "prior_kept_samples", "false_changes",
              "unchanged_pred_samples", "unchanged_pred_on_map", "unchanged_gt_samples", "unchanged_gt_found"]


def shifted(points, dv):
    return [(u, v + dv) for u, v in points]


def cases():
    """(key, current, prior, prediction) of every case."""
    road = lane([(20, 100), (236, 100)])
    second = lane([(20, 120), (236, 120)])
    out = []
    # a lane added beside a kept one (20 px = 4 m south)
    cur = graph((road, UNCHANGED), (second, ADDED))
    pri = graph((road, UNCHANGED))
    out += [("added-follows-current", cur, pri, cur),
            ("added-copies-prior", cur, pri, pri),
            ("added-half-found", cur, pri, graph((road, 0), (lane([(20, 120), (128, 120)]), 0)))]
    # a lane removed (closed) beside a kept one
    cur = graph((road, UNCHANGED))
    pri = graph((road, UNCHANGED), (second, REMOVED))
    out += [("removed-follows-current", cur, pri, graph((shifted(road, 3), 0))),
            ("removed-copies-prior", cur, pri, pri),
            ("removed-kept-half", cur, pri, graph((road, 0), (lane([(128, 120), (236, 120)]), 0)))]
    # a lane moved 20 px; the prediction halfway (10 px from both: neither place)
    cur = graph((road, UNCHANGED), (second, MOVED))
    pri = graph((road, UNCHANGED), (lane([(20, 140), (236, 140)]), MOVED))
    out += [("moved-follows-current", cur, pri, cur),
            ("moved-copies-prior", cur, pri, pri),
            ("moved-halfway", cur, pri, graph((road, 0), (lane([(20, 130), (236, 130)]), 0)))]
    # nothing changed: a prediction that drops half the lane and draws one that is not there
    cur = graph((road, UNCHANGED))
    out += [("no-change-false-claims", cur, cur, graph((lane([(20, 100), (128, 100)]), 0),
                                                        (lane([(20, 200), (236, 200)]), 0)))]
    # retyped: the same geometry, a new divider; a change without a change sample
    cur = graph((road, RETYPED))
    pri = graph((road, RETYPED))
    out += [("retyped-copies-prior", cur, pri, pri)]
    # a turn connector added between two kept lanes that meet at a crossing: its ends lie
    # within the match radius of the kept lanes, so only its middle is a change sample
    west = lane([(20, 128), (108, 128)])
    north = lane([(128, 108), (128, 20)])
    turn = lane([(108, 128), (118, 125), (125, 118), (128, 108)])
    cur = graph((west, UNCHANGED), (north, UNCHANGED), (turn, ADDED))
    pri = graph((west, UNCHANGED), (north, UNCHANGED))
    out += [("turn-added-follows-current", cur, pri, cur),
            ("turn-added-copies-prior", cur, pri, pri)]
    return out


def build():
    tiles = {}
    for key, cur, pri, pred in cases():
        tiles[key] = {"gt": cur, "prior": pri, "pred": {"nodes": pred["nodes"], "edges": pred["edges"]},
                      "expect": change_values(cur, pri, pred)}
    return {"about": "map-change cases (docs/metrics.md \"Map change\"): current map (gt), prior map and "
                     "prediction per tile, edge_flags as EdgeFlag bytes (4 unchanged, 8 added, 16 removed, "
                     "32 moved, 64 retyped); made by change_reference.py --write",
            "params": PARAMS, "tiles": tiles}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--write", action="store_true")
    a = ap.parse_args()
    doc = build()
    if a.write:
        with open(CASES_FILE, "w") as f:
            json.dump(doc, f, indent=1, sort_keys=True)
            f.write("\n")
        print(f"change_cases.json: {len(doc['tiles'])} tiles written")
        return 0
    with open(CASES_FILE) as f:
        want = json.load(f)
    bad = 0
    for key, tile in doc["tiles"].items():
        for name, value in tile["expect"].items():
            w = want["tiles"][key]["expect"].get(name)
            if name == "counts":
                if w != value:
                    print(f"{key}.counts: {w} != {value}")
                    bad += 1
            elif (w is None) != (value is None) or (w is not None and abs(w - value) > 1e-9):
                print(f"{key}.{name}: file {w}, computed {value}")
                bad += 1
    print(f"{len(doc['tiles'])} tiles, {bad} differences")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())

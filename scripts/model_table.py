#!/usr/bin/python3
"""The reference model's tables from `nsgraph score` reports: Table II (the variants) and
its junction metrics (metrics v2: split detection, junction TOPO, GEO recall in and out of
intersections), the input ablation, the per-tile paired differences between variants (mean ± standard error),
and a check of every row against committed values (scripts/model-expected.json).

  model_table.py --dir demo-out/baselines --rows b1 b2 graph \
      [--ablation-dir demo-out/ablation --ablation lidar lidar+rgb ...] [--expected FILE]

Each row NAME reads DIR/NAME.score.json (and DIR/NAME.time.json for the train seconds, if
there). Writes DIR/baselines.{md,json} (or, with --ablation-only, ABLATION_DIR/ablation.*)
and prints the Markdown. Exit 1 when a row's metric is below its committed value by more
than the tolerance (or undefined), 0 otherwise. Only the rows this run made are checked.
"""
import argparse
import json
import math
import os
import sys

METRICS = ["apls", "f1", "iou", "chamfer_mean_m", "direction_accuracy", "topo_f1"]
# Where models fail (docs/metrics.md "Metrics v2"); SDA is a mean over the tiles with a
# ground-truth split, the per-class recalls over the tiles with lanes of the class.
JUNCTION_METRICS = ["sda20_precision", "sda20_recall", "sda50_precision", "sda50_recall", "jtopo_f1",
                    "geo_recall_in_intersection", "geo_recall_outside_intersection"]
JUNCTION_HEADERS = ["SDA@20 P", "SDA@20 R", "SDA@50 P", "SDA@50 R", "JTOPO F1", "GEO R in intersections",
                    "GEO R outside"]
HIGHER_IS_BETTER = {"apls", "f1", "iou", "direction_accuracy", "topo_f1"} | set(JUNCTION_METRICS)
VARIANT_LABELS = {"b1": "b1: skeletonized centreline regression", "b2": "b2: anchors + two nearest neighbours",
                  "graph": "graph: anchors + has-connection classifier",
                  "net": "net: LaneGraphNet (PyTorch → ONNX, C++ predict)"}
ABLATION_LABELS = {"lidar": "LiDAR only", "lidar+rgb": "LiDAR + RGB", "lidar+semantic": "LiDAR + semantics",
                   "lidar+vehicle": "LiDAR + vehicles", "all": "all (LiDAR + RGB + semantics + vehicles)"}
# The differences docs/reference-model.md quotes: (a, b, metric) → a − b per tile.
PAIRS = [("graph", "b1", "apls"), ("graph", "b1", "f1"), ("graph", "b1", "topo_f1"),
         ("graph", "b2", "apls"), ("graph", "b2", "f1"), ("graph", "b2", "topo_f1"),
         ("net", "graph", "apls"), ("net", "graph", "f1"), ("net", "graph", "topo_f1"),
         ("graph", "b1", "sda50_recall"), ("graph", "b1", "jtopo_f1"), ("net", "graph", "sda50_recall"),
         ("net", "graph", "jtopo_f1")]


def load_row(folder, name):
    """Aggregate means, per-tile values and train seconds of one run."""
    with open(os.path.join(folder, f"{name}.score.json")) as f:
        rep = json.load(f)
    row = {"name": name, "tiles": rep["aggregate"]["n_tiles"],
           "mean": {m: rep["aggregate"]["mean"].get(m) for m in METRICS + JUNCTION_METRICS},
           "per_tile": {key: {m: t.get(m) for m in METRICS + JUNCTION_METRICS} for key, t in rep["tiles"].items()}}
    try:
        with open(os.path.join(folder, f"{name}.time.json")) as f:
            row["train_s"] = json.load(f)["train_s"]
    except OSError:
        row["train_s"] = None
    return row


def paired_difference(a, b, metric):
    """Mean and standard error of a − b over the tiles where both are defined."""
    diffs = [ta[metric] - b["per_tile"][k][metric] for k, ta in a["per_tile"].items()
             if ta.get(metric) is not None and k in b["per_tile"] and b["per_tile"][k].get(metric) is not None]
    n = len(diffs)
    if n == 0:
        return {"n": 0, "mean": None, "se": None}
    mean = sum(diffs) / n
    se = math.sqrt(sum((d - mean) ** 2 for d in diffs) / (n - 1) / n) if n > 1 else None
    return {"n": n, "mean": mean, "se": se}


def check_rows(rows, expected):
    """Rows against the committed values: a list of (row, metric, value, committed, tolerance, ok).
    A row may carry its own "_tolerance" (the network's: its training repeats only on the same machine)."""
    out = []
    for name, committed in expected.get("rows", {}).items():
        row = rows.get(name)
        tol = committed.get("_tolerance", expected.get("tolerance", 0.015))
        for metric, value_then in committed.items():
            if metric.startswith("_"):
                continue
            value = row["mean"].get(metric) if row else None
            if value is None:
                ok = False
            elif metric in HIGHER_IS_BETTER:
                ok = value >= value_then - tol
            else:
                ok = value <= value_then + tol
            out.append({"row": name, "metric": metric, "value": value, "committed": value_then, "tolerance": tol,
                        "ok": ok})
    return out


def fmt(x, spec=".3f"):
    return "—" if x is None else f"{x:{spec}}"


def row_line(label, row, metrics):
    cells = " | ".join(fmt(row["mean"][m]) for m in metrics)
    return f"| {label} | {cells} | {fmt(row['train_s'], '.0f')} |"


def markdown(variants, ablation, pairs, checks):
    lines = []
    if variants:
        tiles = variants[0]["tiles"]
        lines += [f"| variant (synthetic demo test split, {tiles} tiles) | APLS | F1 | IoU | Chamfer mean m | "
                  "direction acc. | TOPO F1 | train s |", "|---|---:|---:|---:|---:|---:|---:|---:|"]
        lines += [row_line(VARIANT_LABELS.get(r["name"], r["name"]), r, METRICS) for r in variants]
        lines.append("")
        lines += [f"| variant, junction metrics ({tiles} tiles) | " + " | ".join(JUNCTION_HEADERS) + " |",
                  "|---|" + "---:|" * len(JUNCTION_HEADERS)]
        for r in variants:
            cells = " | ".join(fmt(r["mean"][m]) for m in JUNCTION_METRICS)
            lines.append(f"| {VARIANT_LABELS.get(r['name'], r['name'])} | {cells} |")
        lines.append("")
    if ablation:
        metrics = ["apls", "f1", "iou", "direction_accuracy", "topo_f1"]
        lines += ["| inputs (graph variant, synthetic demo test split) | APLS | F1 | IoU | direction acc. | TOPO F1 | "
                  "train s |", "|---|---:|---:|---:|---:|---:|---:|"]
        lines += [row_line(ABLATION_LABELS.get(r["name"], r["name"]), r, metrics) for r in ablation]
        lines.append("")
    if pairs:
        lines += ["| per-tile paired difference | mean ± s.e. | tiles |", "|---|---:|---:|"]
        for p in pairs:
            lines.append(f"| {p['a']} − {p['b']}, {p['metric']} | {fmt(p['mean'], '+.3f')} ± {fmt(p['se'])} | "
                         f"{p['n']} |")
        lines.append("")
    if checks:
        missed = [c for c in checks if not c["ok"]]
        tol = checks[0]["tolerance"]
        lines.append(f"Against the committed values (scripts/model-expected.json, tolerance {tol}): "
                     + ("every row holds." if not missed else "DROPPED: " + "; ".join(
                         f"{c['row']} {c['metric']} {fmt(c['value'])} (committed {c['committed']:.3f})"
                         for c in missed)))
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--dir", help="folder of the variants' runs")
    ap.add_argument("--rows", nargs="*", default=[], help="variant runs in --dir (NAME.score.json)")
    ap.add_argument("--ablation-dir", help="folder of the ablation's runs (default: --dir)")
    ap.add_argument("--ablation", nargs="*", default=[], help="ablation runs (NAME.score.json)")
    ap.add_argument("--expected", default=os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                                         "model-expected.json"))
    ap.add_argument("--no-check", action="store_true", help="write the tables only")
    a = ap.parse_args()
    out_dir = a.dir or a.ablation_dir
    if not out_dir:
        ap.error("--dir or --ablation-dir is needed")
    ablation_dir = a.ablation_dir or a.dir
    variants = [load_row(a.dir, n) for n in a.rows]
    ablation = [load_row(ablation_dir, n) for n in a.ablation]
    by_name = {r["name"]: r for r in variants}
    by_name.update({f"ablation:{r['name']}": r for r in ablation})
    pairs = [dict(a=x, b=y, metric=m, **paired_difference(by_name[x], by_name[y], m))
             for x, y, m in PAIRS if x in by_name and y in by_name]
    checks = []
    if not a.no_check:
        with open(a.expected) as f:
            expected = json.load(f)
        # Only the rows this run made: `make ablation` alone checks the ablation's rows.
        wanted = {k: v for k, v in expected["rows"].items() if k in by_name}
        checks = check_rows(by_name, dict(expected, rows=wanted))
    md = markdown(variants, ablation, pairs, checks)
    stem = "baselines" if variants else "ablation"
    result = {"variants": [{k: r[k] for k in ("name", "tiles", "mean", "train_s")} for r in variants],
              "ablation": [{k: r[k] for k in ("name", "tiles", "mean", "train_s")} for r in ablation],
              "paired_differences": pairs, "checks": checks}
    with open(os.path.join(out_dir, f"{stem}.json"), "w") as f:
        json.dump(result, f, indent=1)
    with open(os.path.join(out_dir, f"{stem}.md"), "w") as f:
        f.write(md)
    print("\n" + md, end="")
    missed = [c for c in checks if not c["ok"]]
    if missed:
        print(f"model_table: {len(missed)} figure(s) dropped beyond the tolerance", file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()

"""The observation ladder's table and curves (scripts/ladder.sh): the per-rung scores of the
models (the forest and LaneGraphNet, each trained on every scene / on rung 1) and the
coverage of the test tiles per rung.

Reads DIR/score-<model>.json (nsgraph score's `rungs`) of the models MODELS names — the
forest's always, LaneGraphNet's when ladder.sh made them (NSG_SKIP_NET=1 leaves them out) —
and the ladder dataset's test tiles (DIR/dataset, read with tarfile and json); writes
DIR/ladder.json, DIR/ladder.md and DIR/ladder.svg (APLS and TOPO F1 against the rung, ± one
standard error) and prints the Markdown. Exits 1 when a figure is worse than
scripts/model-expected.json's ladder rows by more than their tolerance (rows named
ladder:<model>:<rung>; a row of a model that was not run is not checked).
"""
import argparse
import json
import os
import sys
import tarfile

METRICS = ("apls", "f1", "topo_f1", "jtopo_f1", "direction_accuracy")
# (score file's tag, label, colour, dashed): the forest's two, then LaneGraphNet's two.
MODELS = (("all", "forest, trained on every scene", "#1f5fbf", False),
          ("r1", "forest, trained on rung 1", "#c0392b", False),
          ("net-all", "LaneGraphNet, trained on every scene", "#1f5fbf", True),
          ("net-r1", "LaneGraphNet, trained on rung 1", "#c0392b", True))


def coverage_per_rung(dataset):
    """Mean LiDAR and RGB coverage of the test tiles at each rung (\"all\" = the split tiles)."""
    manifest = json.load(open(os.path.join(dataset, "manifest.json")))
    shards = [("all", s) for s in manifest["shards"] if s["split"] == "test"]
    shards += [(str(s["rung"]), s) for s in manifest.get("ladder", {}).get("shards", []) if s["split"] == "test"]
    sums = {}
    for rung, shard in shards:
        with tarfile.open(os.path.join(dataset, shard["file"])) as tar:
            for m in tar.getmembers():
                if m.name.endswith(".meta.json"):
                    meta = json.load(tar.extractfile(m))
                    s = sums.setdefault(rung, [0, 0.0, 0.0, 0])
                    s[0] += 1
                    s[1] += meta["coverage"]["lidar"]
                    s[2] += meta["coverage"]["rgb"]
                    s[3] += len(meta["scenes"])
    return {r: {"tiles": n, "lidar": l / n, "rgb": c / n, "scenes": k / n} for r, (n, l, c, k) in sums.items()}


def svg(results, path):
    """Two panels (APLS, TOPO F1): one line per model over the rungs (LaneGraphNet's dashed),
    error bars ± 1 SE."""
    W, H, L, B, T, R = 330, 210, 44, 30, 24, 12
    models = [m for m in MODELS if m[0] in results]
    legend_rows = (len(models) + 1) // 2
    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{2 * W}" height="{H + 10 + 14 * legend_rows}" '
             'font-family="sans-serif" font-size="11">']
    for panel, metric in enumerate(("apls", "topo_f1")):
        x0 = panel * W
        rungs = [r["rung"] for r in results["all"]["rungs"]]
        vals = [(r["metrics"][metric]["mean"] or 0, r["metrics"][metric]["se"] or 0)
                for m in results for r in results[m]["rungs"]]
        lo = max(0.0, min(v - e for v, e in vals) - 0.02)
        hi = min(1.0, max(v + e for v, e in vals) + 0.02)
        x = lambda i: x0 + L + i * (W - L - R) / max(1, len(rungs) - 1)
        y = lambda v: T + (hi - v) / (hi - lo) * (H - T - B)
        parts.append(f'<text x="{x0 + L}" y="14" font-weight="bold">{metric} (mean over test tiles ± 1 SE)</text>')
        parts.append(f'<line x1="{x0 + L}" y1="{H - B}" x2="{x0 + W - R}" y2="{H - B}" stroke="#888"/>')
        for i, r in enumerate(rungs):
            parts.append(f'<text x="{x(i):.1f}" y="{H - B + 16}" text-anchor="middle">{r}</text>')
        for v in (lo, (lo + hi) / 2, hi):
            parts.append(f'<text x="{x0 + L - 4}" y="{y(v) + 4:.1f}" text-anchor="end">{v:.2f}</text>')
        for model, _, colour, dashed in models:
            pts = [(i, r["metrics"][metric]) for i, r in enumerate(results[model]["rungs"])]
            line = " ".join(f"{x(i):.1f},{y(m['mean']):.1f}" for i, m in pts if m["mean"] is not None)
            dash = ' stroke-dasharray="6 3"' if dashed else ""
            parts.append(f'<polyline fill="none" stroke="{colour}" stroke-width="2"{dash} points="{line}"/>')
            for i, m in pts:
                if m["mean"] is None:
                    continue
                se = m["se"] or 0
                parts.append(f'<line x1="{x(i):.1f}" x2="{x(i):.1f}" y1="{y(m["mean"] - se):.1f}" '
                             f'y2="{y(m["mean"] + se):.1f}" stroke="{colour}"/>')
                parts.append(f'<circle cx="{x(i):.1f}" cy="{y(m["mean"]):.1f}" r="3" fill="{colour}"/>')
        parts.append(f'<text x="{x0 + (W + L) / 2}" y="{H + 8}" text-anchor="middle">rung (drives per tile)</text>')
    for k, (_, label, colour, dashed) in enumerate(models):
        parts.append(f'<text x="{L + (k % 2) * W}" y="{H + 22 + 14 * (k // 2)}" fill="{colour}">'
                     f'{"- - " if dashed else "— "}{label}</text>')
    parts.append("</svg>\n")
    open(path, "w").write("\n".join(parts))


def time_split(dir):
    """The before-after preset's dataset of the demo world (DIR/time, ladder.sh): its leakage
    figures (manifest locations[].time_split) and the forest's scores on its test split; None
    when ladder.sh did not make it."""
    manifest, score = os.path.join(dir, "time", "manifest.json"), os.path.join(dir, "score-time.json")
    if not (os.path.exists(manifest) and os.path.exists(score)):
        return None
    m = json.load(open(manifest))
    mean = json.load(open(score))["aggregate"]["mean"]
    out = {"locations": {loc["name"]: loc["time_split"] for loc in m["locations"]},
           "tiles": {split: c["tiles"] for split, c in m["counts"].items() if isinstance(c, dict)},
           "forest": {k: mean[k] for k in METRICS}}
    return out


def time_split_md(t):
    rows = ["| location | date | scenes before / on or after | train tiles | test tiles | "
            "test tiles overlapping a train tile | median distance to a train tile (m) | "
            + " | ".join(f"forest {m}" for m in METRICS) + " |", "|" + " --- |" * (7 + len(METRICS))]
    for name, ts in t["locations"].items():
        scenes = " / ".join(str(v) for v in ts["scenes"].values())
        rows.append(f"| {name} | {ts['date']} | {scenes} | {t['tiles'].get('train', 0)} | {ts['test_tiles']} | "
                    f"{ts['test_tiles_overlapping_train']} | {ts['median_distance_to_train_m']} | "
                    + " | ".join("—" if t["forest"][m] is None else f"{t['forest'][m]:.3f}" for m in METRICS) + " |")
    return "\n".join(rows) + "\n"


def check(results, ts, expected):
    """Figures below the committed rows: ladder:<model>:<rung> against the per-rung means,
    time_split:forest against the time split's forest scores (rows of runs not made are
    skipped). A row may carry its own "_tolerance" (LaneGraphNet's: its CPU training repeats
    bit for bit only on the same machine)."""
    missed = []
    for name, want in expected["rows"].items():
        if name.startswith("ladder:"):
            _, model, rung = name.split(":")
            if model not in results:
                continue
            got = {k: v["mean"] for k, v in next(r for r in results[model]["rungs"] if r["rung"] == rung)["metrics"].items()}
        elif name == "time_split:forest" and ts:
            got = ts["forest"]
        else:
            continue
        tol = want.get("_tolerance", expected["tolerance"])
        for metric, value in want.items():
            if metric.startswith("_"):
                continue
            have = got[metric]
            if have is None or have < value - tol:
                missed.append(f"{name} {metric}: {have} < {value} - {tol}")
    return missed


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--dir", required=True)
    ap.add_argument("--expected", default=os.path.join(os.path.dirname(__file__), "model-expected.json"))
    a = ap.parse_args()
    results = {m: json.load(open(os.path.join(a.dir, f"score-{m}.json"))) for m, *_ in MODELS
               if m in ("all", "r1") or os.path.exists(os.path.join(a.dir, f"score-{m}.json"))}
    cov = coverage_per_rung(os.path.join(a.dir, "dataset"))
    lines = ["| model | rung | test tiles | scenes per tile | LiDAR coverage | RGB coverage | "
             + " | ".join(METRICS) + " |", "|" + " --- |" * (6 + len(METRICS))]
    for model, label, *_ in MODELS:
        for r in results.get(model, {"rungs": []})["rungs"]:
            c = cov[r["rung"]]
            cells = [f"{r['metrics'][m]['mean']:.3f} ± {r['metrics'][m]['se']:.3f}"
                     if r["metrics"][m]["mean"] is not None else "—" for m in METRICS]
            lines.append(f"| {label} | {r['rung']} | {r['tiles']} | {c['scenes']:.2f} | {c['lidar']:.3f} | "
                         f"{c['rgb']:.3f} | " + " | ".join(cells) + " |")
    md = "\n".join(lines) + "\n"
    ts = time_split(a.dir)
    if ts:
        md += "\nTime split (splits.preset before-after) of the same world:\n\n" + time_split_md(ts)
    json.dump({"coverage": cov, "models": {m: r["rungs"] for m, r in results.items()}, "time_split": ts},
              open(os.path.join(a.dir, "ladder.json"), "w"), indent=1)
    open(os.path.join(a.dir, "ladder.md"), "w").write(md)
    svg(results, os.path.join(a.dir, "ladder.svg"))
    print(md)
    missed = check(results, ts, json.load(open(a.expected)))
    if missed:
        print("ladder_table: figures below the committed ones:\n  " + "\n  ".join(missed), file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()

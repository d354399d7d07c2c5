"""The observation ladder's table and curves (scripts/ladder.sh): the per-rung scores of the
two models (trained on every scene / on rung 1) and the coverage of the test tiles per rung.

Reads DIR/score-{all,r1}.json (nsgraph score's `rungs`) and the ladder dataset's test tiles
(DIR/dataset, read with tarfile and json); writes DIR/ladder.json, DIR/ladder.md and
DIR/ladder.svg (APLS and TOPO F1 against the rung, ± one standard error) and prints the
Markdown. Exits 1 when a figure is worse than scripts/model-expected.json's ladder rows by
more than their tolerance (rows named ladder:<model>:<rung>).
"""
import argparse
import json
import os
import sys
import tarfile

METRICS = ("apls", "f1", "topo_f1", "jtopo_f1", "direction_accuracy")
MODELS = (("all", "trained on every scene"), ("r1", "trained on rung 1"))


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
    """Two panels (APLS, TOPO F1): one line per model over the rungs, error bars ± 1 SE."""
    W, H, L, B, T, R = 330, 210, 44, 30, 24, 12
    colours = {"all": "#1f5fbf", "r1": "#c0392b"}
    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{2 * W}" height="{H + 24}" font-family="sans-serif" '
             'font-size="11">']
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
        for model, _ in MODELS:
            pts = [(i, r["metrics"][metric]) for i, r in enumerate(results[model]["rungs"])]
            line = " ".join(f"{x(i):.1f},{y(m['mean']):.1f}" for i, m in pts if m["mean"] is not None)
            parts.append(f'<polyline fill="none" stroke="{colours[model]}" stroke-width="2" points="{line}"/>')
            for i, m in pts:
                if m["mean"] is None:
                    continue
                se = m["se"] or 0
                parts.append(f'<line x1="{x(i):.1f}" x2="{x(i):.1f}" y1="{y(m["mean"] - se):.1f}" '
                             f'y2="{y(m["mean"] + se):.1f}" stroke="{colours[model]}"/>')
                parts.append(f'<circle cx="{x(i):.1f}" cy="{y(m["mean"]):.1f}" r="3" fill="{colours[model]}"/>')
        parts.append(f'<text x="{x0 + (W + L) / 2}" y="{H + 8}" text-anchor="middle">rung (drives per tile)</text>')
    for k, (model, label) in enumerate(MODELS):
        parts.append(f'<text x="{L + k * 200}" y="{H + 22}" fill="{colours[model]}">— model {label}</text>')
    parts.append("</svg>\n")
    open(path, "w").write("\n".join(parts))


def check(results, expected):
    tol = expected["tolerance"]
    missed = []
    for name, want in expected["rows"].items():
        if not name.startswith("ladder:"):
            continue
        _, model, rung = name.split(":")
        got = next(r for r in results[model]["rungs"] if r["rung"] == rung)["metrics"]
        for metric, value in want.items():
            have = got[metric]["mean"]
            if have is None or have < value - tol:
                missed.append(f"{name} {metric}: {have} < {value} - {tol}")
    return missed


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--dir", required=True)
    ap.add_argument("--expected", default=os.path.join(os.path.dirname(__file__), "model-expected.json"))
    a = ap.parse_args()
    results = {m: json.load(open(os.path.join(a.dir, f"score-{m}.json"))) for m, _ in MODELS}
    cov = coverage_per_rung(os.path.join(a.dir, "dataset"))
    lines = ["| model | rung | test tiles | scenes per tile | LiDAR coverage | RGB coverage | "
             + " | ".join(METRICS) + " |", "|" + " --- |" * (6 + len(METRICS))]
    for model, label in MODELS:
        for r in results[model]["rungs"]:
            c = cov[r["rung"]]
            cells = [f"{r['metrics'][m]['mean']:.3f} ± {r['metrics'][m]['se']:.3f}"
                     if r["metrics"][m]["mean"] is not None else "—" for m in METRICS]
            lines.append(f"| {label} | {r['rung']} | {r['tiles']} | {c['scenes']:.2f} | {c['lidar']:.3f} | "
                         f"{c['rgb']:.3f} | " + " | ".join(cells) + " |")
    md = "\n".join(lines) + "\n"
    json.dump({"coverage": cov, "models": {m: results[m]["rungs"] for m, _ in MODELS}},
              open(os.path.join(a.dir, "ladder.json"), "w"), indent=1)
    open(os.path.join(a.dir, "ladder.md"), "w").write(md)
    svg(results, os.path.join(a.dir, "ladder.svg"))
    print(md)
    missed = check(results, json.load(open(a.expected)))
    if missed:
        print("ladder_table: figures below the committed ones:\n  " + "\n  ".join(missed), file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()

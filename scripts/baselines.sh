#!/usr/bin/env bash
# `make baselines`: the paper's Table II on the demo dataset — the reference model's three
# variants (b1 skeletonized centrelines, b2 anchors + two nearest neighbours, graph anchors
# + a trained has-connection classifier), each trained on the train split with the same
# seed and scored on the test split. Writes demo-out/baselines/{baselines.json,baselines.md}
# and prints the Markdown table.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
# shellcheck source=scripts/model_runs.sh
source "$root/scripts/model_runs.sh" "${1:-build}" baselines
ensure_demo_dataset
rows=("b1" "b2" "graph")
for v in "${rows[@]}"; do
  run_model "$dir" "$v" --variant "$v"
done
if [ "${NSG_SKIP_NET:-0}" != 1 ]; then bash "$root/scripts/net_baseline.sh" "${1:-build}"; rows+=("net"); fi

"$py" - "$dir" "${rows[@]}" <<'PY'
import json, sys
d, rows = sys.argv[1], sys.argv[2:]
labels = {"b1": "B1: skeletonized centreline regression", "b2": "B2: anchors + two nearest neighbours",
          "graph": "graph: anchors + has-connection classifier"}
table, result = [], []
for v in rows:
    rep = json.load(open(f"{d}/{v}.score.json"))
    t = json.load(open(f"{d}/{v}.time.json"))
    mean = rep["aggregate"]["mean"]
    r = {"variant": v, "apls": mean["apls"], "f1": mean["f1"], "iou": mean["iou"],
         "chamfer_mean_m": mean["chamfer_mean_m"], "direction_accuracy": mean["direction_accuracy"],
         "topo_f1": mean["topo_f1"], "tiles": rep["aggregate"]["n_tiles"], "train_s": t["train_s"],
         "predict_s_incl_load": t["predict_s"]}
    result.append(r)
    f = lambda x: "—" if x is None else f"{x:.3f}"
    table.append(f"| {labels.get(v, v)} | {f(r['apls'])} | {f(r['f1'])} | {f(r['iou'])} | {f(r['chamfer_mean_m'])} | "
                 f"{f(r['direction_accuracy'])} | {f(r['topo_f1'])} | {r['train_s']:.0f} |")
tiles = result[0]["tiles"] if result else 0
md = (f"| variant (synthetic demo test split, {tiles} tiles) | APLS | F1 | IoU | Chamfer mean m | direction acc. | "
      "TOPO F1 | train s |\n|---|---:|---:|---:|---:|---:|---:|---:|\n" + "\n".join(table) + "\n")
json.dump(result, open(f"{d}/baselines.json", "w"), indent=1)
open(f"{d}/baselines.md", "w").write(md)
print("\n" + md)
PY

#!/usr/bin/env bash
# `make ablation`: the paper's input ablation with the reference model on the demo dataset —
# one model per modality set, trained on the train split and scored on the test split.
# Writes demo-out/ablation/{ablation.json,ablation.md} and prints the Markdown table.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
# shellcheck source=scripts/model_runs.sh
source "$root/scripts/model_runs.sh" "${1:-build}" ablation
ensure_demo_dataset
rows=("lidar" "lidar,rgb" "lidar,semantic" "lidar,vehicle" "all")
for m in "${rows[@]}"; do
  run_model "$dir" "${m//,/+}" --modalities "$m"
done

"$py" - "$dir" "${rows[@]}" <<'PY'
import json, sys
d, rows = sys.argv[1], sys.argv[2:]
labels = {"lidar": "LiDAR only", "lidar,rgb": "LiDAR + RGB", "lidar,semantic": "LiDAR + semantics",
          "lidar,vehicle": "LiDAR + vehicles", "all": "all (LiDAR + RGB + semantics + vehicles)"}
table, result = [], []
for m in rows:
    n = m.replace(",", "+")
    rep = json.load(open(f"{d}/{n}.score.json"))
    t = json.load(open(f"{d}/{n}.time.json"))
    mean = rep["aggregate"]["mean"]
    r = {"modalities": m, "apls": mean["apls"], "f1": mean["f1"], "iou": mean["iou"],
         "direction_accuracy": mean["direction_accuracy"], "topo_f1": mean["topo_f1"],
         "tiles": rep["aggregate"]["n_tiles"], "train_s": t["train_s"], "predict_s_incl_load": t["predict_s"]}
    result.append(r)
    f = lambda x: "—" if x is None else f"{x:.3f}"
    table.append(f"| {labels.get(m, m)} | {f(r['apls'])} | {f(r['f1'])} | {f(r['iou'])} | "
                 f"{f(r['direction_accuracy'])} | {f(r['topo_f1'])} | {r['train_s']:.0f} |")
md = ("| inputs (reference model, synthetic demo test split) | APLS | F1 | IoU | direction acc. | TOPO F1 | train s |\n"
      "|---|---:|---:|---:|---:|---:|---:|\n" + "\n".join(table) + "\n")
json.dump(result, open(f"{d}/ablation.json", "w"), indent=1)
open(f"{d}/ablation.md", "w").write(md)
print("\n" + md)
PY

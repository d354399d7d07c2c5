#!/usr/bin/env bash
# `make baselines`: the paper's Table II on the demo dataset — the reference model's three
# variants (b1 skeletonized centrelines, b2 anchors + two nearest neighbours, graph anchors
# + a trained has-connection classifier), each trained on the train split with the same
# seed and scored on the test split — and the input ablation of the graph variant beside
# them. Writes demo-out/baselines/{baselines.json,baselines.md} (scripts/model_table.py) and
# prints the Markdown tables; fails when a row drops below scripts/model-expected.json.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
# shellcheck source=scripts/model_runs.sh
source "$root/scripts/model_runs.sh" "${1:-build}" baselines
ensure_demo_dataset
rows=("b1" "b2" "graph")
for v in "${rows[@]}"; do
  run_model "$dir" "$v" --variant "$v"
done
# LaneGraphNet's row (minutes of PyTorch training): NSG_SKIP_NET=1 leaves it out.
if [ "${NSG_SKIP_NET:-0}" != 1 ]; then bash "$root/scripts/net_baseline.sh" "${1:-build}"; rows+=("net"); fi
# The ablation beside Table II (the graph variant, one input set each); "all" is the graph row.
ablation=("lidar" "lidar,rgb" "lidar,semantic" "lidar,vehicle")
for m in "${ablation[@]}"; do
  run_model "$dir" "${m//,/+}" --modalities "$m"
done
cp "$dir/graph.score.json" "$dir/all.score.json"
cp "$dir/graph.time.json" "$dir/all.time.json"

# Table II, the ablation, the per-tile paired differences (mean ± s.e.), and every row
# against scripts/model-expected.json: exit 1 when one dropped beyond the tolerance.
"$py" "$root/scripts/model_table.py" --dir "$dir" --rows "${rows[@]}" \
  --ablation lidar lidar+rgb lidar+semantic lidar+vehicle all

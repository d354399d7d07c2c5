#!/usr/bin/env bash
# `make ablation`: the paper's input ablation with the reference model on the demo dataset —
# one model per modality set, trained on the train split and scored on the test split.
# Writes demo-out/ablation/{ablation.json,ablation.md} (scripts/model_table.py) and prints
# the Markdown table. `make baselines` runs the same rows beside Table II.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
# shellcheck source=scripts/model_runs.sh
source "$root/scripts/model_runs.sh" "${1:-build}" ablation
ensure_demo_dataset
rows=("lidar" "lidar,rgb" "lidar,semantic" "lidar,vehicle" "all")
for m in "${rows[@]}"; do
  run_model "$dir" "${m//,/+}" --modalities "$m"
done

# The table, checked against scripts/model-expected.json (exit 1 when a row dropped).
"$py" "$root/scripts/model_table.py" --ablation-dir "$dir" --ablation "${rows[@]//,/+}"

#!/usr/bin/env bash
# LaneGraphNet's row of `make baselines` (scripts/baselines.sh calls it; NSG_SKIP_NET=1 skips
# it there): trains the PyTorch network on the demo train split (seed 1, 1 thread), chooses
# the relationship head's cut on training tiles (nsgraph.models.calibrate), exports it to
# ONNX and runs `nsgraph predict --model net.onnx` (OpenCV dnn + the C++ post-processing)
# on the test split, then scores it. Writes demo-out/baselines/net.{onnx,
# pairs.onnx,json,score.json,time.json} and the training run in demo-out/baselines/net-run/.
# NSG_NET_EPOCHS sets the epochs (default: the trainer's).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
# shellcheck source=scripts/model_runs.sh
source "$root/scripts/model_runs.sh" "${1:-build}" baselines
ensure_demo_dataset
export PYTHONPATH="$root/${1:-build}/python${PYTHONPATH:+:$PYTHONPATH}"
printf '\n== net (LaneGraphNet, PyTorch → ONNX)\n'
"$py" -m nsgraph.models.train --dataset "$out/dataset" --split train --out "$dir/net-run" --seed 1 --threads 1 \
  ${NSG_NET_EPOCHS:+--epochs "$NSG_NET_EPOCHS"} --resume
start=$(date +%s%N)
"$py" -m nsgraph.models.calibrate --model "$dir/net-run/model.pt" --dataset "$out/dataset" --split train
"$py" -m nsgraph.models.export --model "$dir/net-run/model.pt" --out "$dir/net.onnx"
mid=$(date +%s%N)
"$exe" predict -q --model "$dir/net.onnx" --dataset "$out/dataset" --split test --out "$dir/net.json"
end=$(date +%s%N)
"$exe" score -q --ground-truth "$out/dataset" --submission "$dir/net.json" --split test \
  --out "$dir/net.score.json" >/dev/null
# train_s: the training's own seconds (train.json, summed over resumed runs) + calibration and export.
train_ms=$("$py" -c 'import json, sys; print(round(json.load(open(sys.argv[1]))["train_seconds"] * 1000))' \
  "$dir/net-run/train.json")
echo "{\"train_s\": $((train_ms + (mid - start) / 1000000))e-3, \"predict_s\": $(((end - mid) / 1000000))e-3}" \
  >"$dir/net.time.json"

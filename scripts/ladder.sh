#!/usr/bin/env bash
# `make ladder`: the observation ladder on the demo world (docs/dataset-format.md,
# "Observation ladder"). The demo release's dataset again with rungs 1, 2 and 4 on its train
# and test tiles (generate --ladder); the reference forest and LaneGraphNet each trained twice
# — on the train split (every scene) and on its rung 1 (each tile from its first drive only)
# — and each scored on the test split at every rung (score's per-rung report). Writes
# demo-out/ladder/{ladder.json,ladder.md,ladder.svg} (scripts/ladder_table.py) and prints
# the table; exits 1 when a figure dropped below scripts/model-expected.json's ladder rows.
# Then the demo world's time split (splits.preset before-after at $time_date: the release's
# 170 scenes are spread over 17 days, samples/synth/demo.json scenes.capture_days) with its
# leakage figures and the forest trained before the date, scored after it.
# NSG_SKIP_NET=1 leaves LaneGraphNet out (its two trainings take ~15 min each, run side by
# side on one thread each); NSG_NET_EPOCHS sets their epochs (default: the trainer's).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
# shellcheck source=scripts/model_runs.sh
source "$root/scripts/model_runs.sh" "${1:-build}" ladder
ensure_demo_dataset
config="$root/samples/generate-demo.json"
time_date=2018-08-05
# What the ladder's datasets are made from: the generate config and the release's synth
# config (its capture dates are in the rung tiles' meta.json); a change rebuilds them and
# retrains the networks from scratch (their --resume checkpoints are of the old tiles).
inputs_now=$(cat "$config" "$out/release/.synth-done" | sha256sum)
if [ ! -f "$dir/dataset/manifest.json" ] || [ "$inputs_now" != "$(cat "$dir/.dataset-inputs" 2>/dev/null)" ]; then
  rm -rf "$dir/dataset" "$dir/time" "$dir"/net-*-run  # the networks' checkpoints were of the old tiles
  /usr/bin/time -f 'generate --ladder: %e s wall, %M KiB peak RSS' \
    "$exe" generate -q --config "$config" --dataroot "$out/release" --out "$dir/dataset" --ladder \
    --set 'ladder.splits=["train", "test"]'
  echo "$inputs_now" >"$dir/.dataset-inputs"
fi
# A model's predictions at every rung of the test split, one submission, scored per rung:
# score-<tag>.json.
score_at_every_rung() {
  local model=$1 tag=$2 parts=()
  for rung in "" -r1 -r2 -r4; do
    "$exe" predict -q --model "$model" --dataset "$dir/dataset" --split "test$rung" --out "$dir/pred-$tag-test$rung.json"
    parts+=("$dir/pred-$tag-test$rung.json")
  done
  "$py" - "$dir/submission-$tag.json" "${parts[@]}" <<'PY'
import json, sys
tiles = {}
for part in sys.argv[2:]:
    tiles.update(json.load(open(part))["tiles"])
json.dump({"schema_version": "1", "tiles": tiles}, open(sys.argv[1], "w"))
PY
  "$exe" score -q --ground-truth "$dir/dataset" --submission "$dir/submission-$tag.json" --split test \
    --out "$dir/score-$tag.json" >/dev/null
}

# The split a model of `tag` trains on: every scene (all) or rung 1 (r1).
train_split() { if [ "$1" = all ]; then echo train; else echo "train-$1"; fi; }

# The forest: trained on every scene (the paper's setting) and on rung 1 (one traversal per tile).
for model in all r1; do
  printf '\n== forest trained on %s\n' "$(train_split $model)"
  "$exe" train -q --dataset "$dir/dataset" --split "$(train_split $model)" --model "$dir/model-$model.yml.gz"
  score_at_every_rung "$dir/model-$model.yml.gz" "$model"
done

# LaneGraphNet the same two ways (as scripts/net_baseline.sh trains it: seed 1, one thread,
# the relationship head's cut chosen on the training split), both trainings side by side.
if [ "${NSG_SKIP_NET:-0}" != 1 ]; then
  export PYTHONPATH="$root/${1:-build}/python${PYTHONPATH:+:$PYTHONPATH}"
  pids=()
  for model in all r1; do
    printf '\n== LaneGraphNet trained on %s (log: %s)\n' "$(train_split $model)" "$dir/net-$model-train.log"
    "$py" -m nsgraph.models.train --dataset "$dir/dataset" --split "$(train_split $model)" --out "$dir/net-$model-run" \
      --seed 1 --threads 1 ${NSG_NET_EPOCHS:+--epochs "$NSG_NET_EPOCHS"} --resume --quiet >"$dir/net-$model-train.log" 2>&1 &
    pids+=($!)
  done
  for pid in "${pids[@]}"; do wait "$pid"; done
  for model in all r1; do
    "$py" -m nsgraph.models.calibrate --model "$dir/net-$model-run/model.pt" --dataset "$dir/dataset" \
      --split "$(train_split $model)"
    "$py" -m nsgraph.models.export --model "$dir/net-$model-run/model.pt" --out "$dir/net-$model.onnx" >/dev/null
    score_at_every_rung "$dir/net-$model.onnx" "net-$model"
  done
else
  rm -f "$dir"/score-net-*.json  # an earlier run's: the table shows this run's models only
fi
# The time split: train tiles from the scenes captured before $time_date, test tiles from
# those on or after it (the same streets: generate prints the leakage, the manifest keeps it).
printf '\n== time split at %s\n' "$time_date"
if [ ! -f "$dir/time/manifest.json" ]; then
  "$exe" generate -q --config "$config" --dataroot "$out/release" --out "$dir/time" --set 'splits.regions={}' \
    --set splits.preset=before-after --set splits.before_after_date="$time_date"
fi
"$exe" train -q --dataset "$dir/time" --split train --model "$dir/model-time.yml.gz"
"$exe" predict -q --model "$dir/model-time.yml.gz" --dataset "$dir/time" --split test --out "$dir/pred-time.json"
"$exe" score -q --ground-truth "$dir/time" --submission "$dir/pred-time.json" --split test \
  --out "$dir/score-time.json" >/dev/null
"$py" "$root/scripts/ladder_table.py" --dir "$dir"

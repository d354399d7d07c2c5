#!/usr/bin/env bash
# `make ladder`: the observation ladder on the demo world (docs/dataset-format.md,
# "Observation ladder"). The demo release's dataset again with rungs 1, 2 and 4 on its train
# and test tiles (generate --ladder); the reference model trained twice — on the train
# split (every scene) and on its rung 1 (each tile from its first drive only) — and each
# scored on the test split at every rung (score's per-rung report). Writes
# demo-out/ladder/{ladder.json,ladder.md,ladder.svg} (scripts/ladder_table.py) and prints
# the table; exits 1 when a figure dropped below scripts/model-expected.json's ladder rows.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
# shellcheck source=scripts/model_runs.sh
source "$root/scripts/model_runs.sh" "${1:-build}" ladder
ensure_demo_dataset
config="$root/samples/generate-demo.json"
if [ ! -f "$dir/dataset/manifest.json" ] || ! cmp -s "$config" "$dir/.dataset-config.json"; then
  rm -rf "$dir/dataset"
  /usr/bin/time -f 'generate --ladder: %e s wall, %M KiB peak RSS' \
    "$exe" generate -q --config "$config" --dataroot "$out/release" --out "$dir/dataset" --ladder \
    --set 'ladder.splits=["train", "test"]'
  cp "$config" "$dir/.dataset-config.json"
fi
# Two models: every scene (the paper's setting) and rung 1 (one traversal per tile).
for model in all r1; do
  split=train
  [ "$model" = all ] || split="train-$model"
  printf '\n== model trained on %s\n' "$split"
  "$exe" train -q --dataset "$dir/dataset" --split "$split" --model "$dir/model-$model.yml.gz"
  # Its predictions at every rung of the test split, one submission, scored per rung.
  parts=()
  for rung in "" -r1 -r2 -r4; do
    "$exe" predict -q --model "$dir/model-$model.yml.gz" --dataset "$dir/dataset" --split "test$rung" \
      --out "$dir/pred-$model-test$rung.json"
    parts+=("$dir/pred-$model-test$rung.json")
  done
  "$py" - "$dir/submission-$model.json" "${parts[@]}" <<'PY'
import json, sys
tiles = {}
for part in sys.argv[2:]:
    tiles.update(json.load(open(part))["tiles"])
json.dump({"schema_version": "1", "tiles": tiles}, open(sys.argv[1], "w"))
PY
  "$exe" score -q --ground-truth "$dir/dataset" --submission "$dir/submission-$model.json" --split test \
    --out "$dir/score-$model.json" >/dev/null
done
"$py" "$root/scripts/ladder_table.py" --dir "$dir"

#!/usr/bin/env bash
# The pretrained LaneGraphNet shipped in samples/models/, so that `nsgraph predict --model`
# works before anyone trains: the network (python/nsgraph/models) trained on the train split
# of the quick-start world (samples/synth/quickstart.json + samples/generate-quickstart.json,
# 7 tiles of 128 px), seed 1, one torch thread, exported to ONNX. It is a small synthetic
# sample, not a model of real streets.
#
#   scripts/pretrained_model.sh BUILD            (re)writes samples/models/lanegraphnet-quickstart.*
#   scripts/pretrained_model.sh BUILD --check    trains again in a temporary folder; exit 1 when
#                                                either ONNX file differs from the shipped one by a
#                                                byte, or the retrained model's score on the
#                                                quick-start test split differs from the recorded one
# BUILD: the build folder (relative to the repository or absolute). ctest runs --check
# (python/pretrained_model). Byte-identical retraining holds for the same torch build on the
# same kind of CPU (docs/lanegraphnet.md says why).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-build}
[[ $build = /* ]] || build="$root/$build"
mode=${2:-}
exe="$build/tools/nsgraph/nsgraph"
py=/usr/bin/python3
export PYTHONPATH="$build/python${PYTHONPATH:+:$PYTHONPATH}"
models="$root/samples/models"
name=lanegraphnet-quickstart
# The training, declared once here; the JSON beside the model records it.
train_args=(--split train --seed 1 --threads 1 --epochs 600 --batch-size 8 --crop 128)

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$exe" synth -q --config "$root/samples/synth/quickstart.json" --out "$work/release"
"$exe" generate -q --config "$root/samples/generate-quickstart.json" --dataroot "$work/release" --out "$work/dataset"
"$py" -m nsgraph.models.train --dataset "$work/dataset" --out "$work/run" --quiet "${train_args[@]}"
"$py" -m nsgraph.models.export --model "$work/run/model.pt" --out "$work/$name.onnx" >/dev/null
"$exe" predict -q --model "$work/$name.onnx" --dataset "$work/dataset" --split test --out "$work/pred.json"
"$exe" score -q --ground-truth "$work/dataset" --submission "$work/pred.json" --out "$work/score.json" >/dev/null

# The record: how the model was made, its files' sha256 and its score on the quick-start test split.
"$py" - "$work" "$name" "${train_args[*]}" <<'PY' >"$work/$name.json"
import hashlib, json, platform, sys
import torch
work, name, args = sys.argv[1:4]
sha = lambda p: hashlib.sha256(open(p, "rb").read()).hexdigest()
score = json.load(open(f"{work}/score.json"))
cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), platform.machine())
print(json.dumps({
    "model": f"{name}.onnx", "pairs": f"{name}.pairs.onnx",
    "made_by": "scripts/pretrained_model.sh (make pretrained)",
    "training": {"dataset": "samples/synth/quickstart.json + samples/generate-quickstart.json, split train (7 tiles)",
                 "arguments": "python -m nsgraph.models.train " + args},
    "sha256": {f"{name}.onnx": sha(f"{work}/{name}.onnx"), f"{name}.pairs.onnx": sha(f"{work}/{name}.pairs.onnx")},
    "made_with": {"torch": torch.__version__, "cpu": cpu},
    "quickstart_test_score": {k: score["aggregate"]["mean"][k] for k in ("apls", "f1", "iou", "direction_accuracy", "topo_f1")},
    "metrics_version": score["metrics_version"],
}, indent=1))
PY

if [ "$mode" = "--check" ]; then
  # Float kernels differ between CPU families (and torch builds): bytes are promised where
  # both match the record; elsewhere the retrained model must score within 0.05 of it.
  same_machine=$("$py" -c 'import json, sys; a, b = (json.load(open(p))["made_with"] for p in sys.argv[1:]); print(int(a == b))' \
    "$work/$name.json" "$models/$name.json")
  status=0
  if [ "$same_machine" = 1 ]; then
    for f in "$name.onnx" "$name.pairs.onnx"; do
      if ! cmp -s "$work/$f" "$models/$f"; then
        echo "pretrained model: retrained $f differs from samples/models/$f" >&2
        status=1
      fi
    done
  else
    echo "pretrained model: another CPU or torch than the record's ($("$py" -c 'import json, sys; print(json.load(open(sys.argv[1]))["made_with"])' "$models/$name.json")): comparing scores, not bytes"
  fi
  "$py" - "$work/$name.json" "$models/$name.json" "$same_machine" <<'PY' || status=1
import json, sys
new, old = (json.load(open(p))["quickstart_test_score"] for p in sys.argv[1:3])
tolerance = 0.0 if sys.argv[3] == "1" else 0.05
bad = {k: (new[k], old[k]) for k in old if abs(new[k] - old[k]) > tolerance}
if bad:
    sys.exit(f"pretrained model: quick-start scores beyond {tolerance} of the record (retrained, recorded): {bad}")
print(f"pretrained model: retrained {'byte for byte' if tolerance == 0 else 'within 0.05'}; "
      f"APLS {new['apls']:.4f}, F1 {new['f1']:.4f} on the quick-start test split")
PY
  exit $status
fi
mkdir -p "$models"
cp "$work/$name.onnx" "$work/$name.pairs.onnx" "$work/$name.json" "$models/"
echo "wrote samples/models/$name.{onnx,pairs.onnx,json}"

# Sourced by scripts/ablation.sh and scripts/baselines.sh (which set `root`) with the build
# folder and the run's name: sets `exe`, `out` (demo-out), `dir` (demo-out/NAME, created)
# and `py`; gives the demo dataset, and one model's train → predict → score run with its
# timings.
exe="$root/$1/tools/nsgraph/nsgraph"
out="$root/demo-out"
dir="$out/$2"
py=/usr/bin/python3
mkdir -p "$dir"

# The demo release and dataset (as `make demo` builds them) unless they are there and up to
# date with samples/synth/demo.json and samples/generate-demo.json.
ensure_demo_dataset() {
  if [ ! -f "$out/release/.synth-done" ] || ! cmp -s "$root/samples/synth/demo.json" "$out/release/.synth-done"; then
    rm -rf "$out/release" "$out/dataset"
    "$exe" synth --config "$root/samples/synth/demo.json" --out "$out/release"
    cp "$root/samples/synth/demo.json" "$out/release/.synth-done"
  fi
  if [ ! -f "$out/dataset/manifest.json" ] || ! cmp -s "$root/samples/generate-demo.json" "$out/.dataset-config.json"; then
    rm -rf "$out/dataset"
    "$exe" generate --config "$root/samples/generate-demo.json" --dataroot "$out/release" --out "$out/dataset"
    cp "$root/samples/generate-demo.json" "$out/.dataset-config.json"
  fi
}

# run_model DIR NAME [train options...]: trains on the demo dataset's train split, predicts
# and scores its test split; writes DIR/NAME.{yml.gz,json,score.json,time.json}.
run_model() {
  local dir=$1 name=$2 start mid end
  shift 2
  printf '\n== %s\n' "$name"
  start=$(date +%s%N)
  "$exe" train -q --dataset "$out/dataset" --split train "$@" --model "$dir/$name.yml.gz"
  mid=$(date +%s%N)
  "$exe" predict -q --model "$dir/$name.yml.gz" --dataset "$out/dataset" --split test --out "$dir/$name.json"
  end=$(date +%s%N)
  "$exe" score -q --ground-truth "$out/dataset" --submission "$dir/$name.json" --split test \
    --out "$dir/$name.score.json" >/dev/null
  echo "{\"train_s\": $(((mid - start) / 1000000))e-3, \"predict_s\": $(((end - mid) / 1000000))e-3}" >"$dir/$name.time.json"
}

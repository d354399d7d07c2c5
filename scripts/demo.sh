#!/usr/bin/env bash
# `make demo`: the main job on the bundled synthetic sample, as far as the pipeline exists:
# synth → generate → validate → preview → train → predict → score → report. Stages whose command is
# not in this build are listed as "next" instead of failing the demo.
set -euo pipefail
build=${1:-build}
root=$(cd "$(dirname "$0")/.." && pwd)
exe="$root/$build/tools/nsgraph/nsgraph"
out="$root/demo-out"
py=/usr/bin/python3
mkdir -p "$out"

have() {  # have <command>: is the subcommand listed in this build's --help?
  "$exe" --help | sed -n '/^Subcommands:/,$p' | grep -qE "^  $1( |$)"
}
step() { printf '\n== %s\n' "$*"; }
next=()

step "synth: samples/synth/demo.json → $out/release"
if have synth && [ -f "$root/samples/synth/demo.json" ]; then
  if [ -f "$out/release/.synth-done" ] && cmp -s "$root/samples/synth/demo.json" "$out/release/.synth-done"; then
    echo "(up to date; delete $out/release to regenerate)"
  else
    rm -rf "$out/release"
    "$exe" synth --config "$root/samples/synth/demo.json" --out "$out/release"
    cp "$root/samples/synth/demo.json" "$out/release/.synth-done"
  fi
  location=$("$py" -c 'import json,sys; print(json.load(open(sys.argv[1]))["location"])' "$root/samples/synth/demo.json")
  version=$(basename "$(ls -d "$out"/release/v1.0-* | head -1)")
  du -sh "$out/release" | sed 's/^/release size: /'

  step "inspect centerlines ($location, 2 m)"
  "$exe" inspect centerlines --dataroot "$out/release" --location "$location" > "$out/centerlines.json"
  "$py" - "$out/centerlines.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
c = d["centerlines"]
print(f'{sum(x["layer"] == "lane" for x in c)} lanes, {sum(x["layer"] == "lane_connector" for x in c)} connectors, '
      f'{sum(len(x["poses"]) for x in c)} poses, {len(d["edges"])} edges')
PY

  step "inspect sweep (first LiDAR key frame)"
  token=$("$py" - "$out/release/$version" <<'PY'
import json, sys
sd = json.load(open(sys.argv[1] + "/sample_data.json"))
print(next(r["token"] for r in sd if r["is_key_frame"] and "LIDAR_TOP" in r["filename"]))
PY
)
  "$exe" inspect sweep --dataroot "$out/release" --version "$version" --token "$token" --head 3
else
  next+=("synth")
fi

step "inspect graph ($location, lane graph at ≤ 2 m, GeoJSON for QGIS)"
if [ -n "${location:-}" ]; then
  "$exe" inspect graph --dataroot "$out/release" --location "$location" --geojson "$out/lanes.geojson" \
    | "$py" -c 'import json, sys
d = json.load(sys.stdin)
print("%d nodes, %d edges, longest edge %.3f m, %d map defects; GeoJSON: %s"
      % (d["nodes"], d["edges"], d["max_edge_length_m"], len(d["defects"]), d["geojson"]))'
fi

step "generate: samples/generate-demo.json → $out/dataset (paper-like train/test regions)"
if have generate; then
  rm -rf "$out/dataset"
  "$exe" generate --config "$root/samples/generate-demo.json" --dataroot "$out/release" --out "$out/dataset"
  "$py" - "$out/dataset/manifest.json" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
c = m["counts"]
print(f'tiles: {c["train"]["tiles"]} train, {c["val"]["tiles"]} val, {c["test"]["tiles"]} test; '
      f'{len(m["shards"])} shards, {sum(s["bytes"] for s in m["shards"]) / 1e6:.1f} MB')
PY
else
  next+=("generate")
fi

step "validate"
if have validate && [ -f "$out/dataset/manifest.json" ]; then
  "$exe" validate "$out/dataset"
else
  next+=("validate")
fi

step "preview"
if have preview && [ -f "$out/dataset/manifest.json" ]; then
  "$exe" preview "$out/dataset" --out "$out/preview" --split test --max-tiles 16
  "$exe" preview "$out/dataset" --out "$out/preview" --overview
  ls "$out/preview"
else
  next+=("preview")
fi

step "frames: every key frame in the regions, OpenLane-V2's per-frame layout (docs/frames.md)"
if have frames && [ -f "$out/dataset/manifest.json" ]; then
  "$exe" frames --dataset "$out/dataset" --out "$out/frames" --overwrite
  "$py" - "$out/frames/manifest.json" <<'PY'
import json, sys
c = json.load(open(sys.argv[1]))["counts"]
print("frames per split:", c["frames"], "dropped:", {k: v for k, v in c["dropped"].items() if v})
for name, l in c["leakage"].items():
    share = "n/a" if l["share_within_radius"] is None else "%.1f %%" % (100 * l["share_within_radius"])
    median = "n/a" if l["median_distance_m"] is None else "%.1f m" % l["median_distance_m"]
    print(f"leakage ({name}): {share} of {l['test_frames']} test frames within {l['radius_m']} m of a train frame, "
          f"median {median}")
PY
else
  next+=("frames")
fi

step "train: the reference model (default variant: graph) on the train split (lib/model)"
if have train && [ -f "$out/dataset/manifest.json" ]; then
  /usr/bin/time -f 'train: %e s wall, %M KiB peak RSS' \
    "$exe" train --dataset "$out/dataset" --split train --model "$out/model.yml.gz"
else
  next+=("train")
fi

step "predict: lane graphs for the test split"
if have predict && [ -f "$out/model.yml.gz" ]; then
  "$exe" predict --model "$out/model.yml.gz" --dataset "$out/dataset" --split test --out "$out/submission.json"
  "$exe" validate --submission "$out/submission.json" --dataset "$out/dataset" --split test
  "$exe" preview "$out/dataset" --out "$out/preview-prediction" --split test --submission "$out/submission.json" \
    --sort apls --max-tiles 16
else
  next+=("predict")
fi

step "score: the reference model on the demo test split (synthetic data, not comparable to real nuScenes)"
if have score && [ -f "$out/submission.json" ]; then
  "$exe" score --ground-truth "$out/dataset" --submission "$out/submission.json" --split test --format md \
    --out "$out/score.json"
else
  next+=("score")
fi

step "frames baseline: the tile model's graphs stitched and cut around each test frame, scored OpenLane-V2's way"
if have frames && [ -f "$out/model.yml.gz" ] && [ -f "$out/frames/manifest.json" ]; then
  "$exe" predict --model "$out/model.yml.gz" --dataset "$out/dataset" --split test --frames "$out/frames" \
    --out "$out/frames-results.json"
  "$exe" score --frames --graph-metrics --ground-truth "$out/frames" --submission "$out/frames-results.json" --split test \
    --format md --out "$out/frames-score.json"
else
  next+=("frames baseline")
fi

step "report: the scored submission as HTML (open $out/report/index.html; no network needed)"
if have report && [ -f "$out/submission.json" ]; then
  /usr/bin/time -f 'report: %e s wall, %M KiB peak RSS' \
    "$exe" report --dataset "$out/dataset" --submission "$out/submission.json" --out "$out/report"
  du -sh "$out/report" | sed 's/^/report size: /'
else
  next+=("report")
fi

if [ ${#next[@]} -gt 0 ]; then
  printf '\nnext (not in this build yet): %s\n' "${next[*]}"
fi
echo "demo outputs in $out"

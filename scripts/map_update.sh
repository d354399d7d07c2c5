#!/usr/bin/env bash
# `make map-update`: the demo world in map-update mode (docs/generating.md "Map update").
# samples/synth/demo.json synthesized again with map changes from capture day 9 of its 17
# (three edits of each kind), generated with samples/generate-demo.json under
# splits.preset map-update at the changes' date (every tile from the scenes on or after it,
# the prior map's graph beside the current one, every edge labelled), and the copy-the-prior
# baseline (predict --model prior) scored on the test split. Writes demo-out/map-update/
# {release,dataset,prior.json,prior-report.json} and prints the manifest's lane labels and
# the score table; exits 1 when the figures docs/generating.md quotes change.
#   usage: scripts/map_update.sh [build-dir]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-build}
exe="$root/$build/tools/nsgraph/nsgraph"
py=/usr/bin/python3
dir="$root/demo-out/map-update"
mkdir -p "$dir"
changes=(--set changes.from_day=9 --set changes.lanes_closed=3 --set changes.turns_removed=3
         --set changes.turns_added=3 --set changes.dividers_retyped=3 --set changes.crossings_added=3)
stamp=$(printf '%s\n' "${changes[@]}" | cat - "$root/samples/synth/demo.json" | sha256sum)
if [ ! -f "$dir/release/changes.json" ] || [ "$stamp" != "$(cat "$dir/.release-inputs" 2>/dev/null)" ]; then
  rm -rf "$dir/release" "$dir/dataset"
  /usr/bin/time -f 'synth with changes: %e s wall, %M KiB peak RSS' \
    "$exe" synth -q --config "$root/samples/synth/demo.json" --out "$dir/release" "${changes[@]}"
  echo "$stamp" >"$dir/.release-inputs"
fi
date=$("$py" -c 'import json, sys; print(json.load(open(sys.argv[1]))["date"])' "$dir/release/changes.json")
if [ ! -f "$dir/dataset/manifest.json" ]; then
  /usr/bin/time -f 'generate map-update: %e s wall, %M KiB peak RSS' \
    "$exe" generate -q --config "$root/samples/generate-demo.json" --dataroot "$dir/release" --out "$dir/dataset" \
    --set splits.preset=map-update --set "splits.before_after_date=$date"
fi
"$exe" validate -q --dataset "$dir/dataset"
"$exe" predict -q --model prior --dataset "$dir/dataset" --split test --out "$dir/prior.json"
"$py" - "$dir/dataset/manifest.json" "$dir/release/changes.json" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
c = json.load(open(sys.argv[2]))
for loc in m["locations"]:
    u = loc["map_update"]
    print(f'{loc["name"]}: changes from {u["date"]} ({u["scenes"]} scenes on or after it), '
          f'{len(c["edits"])} edits; lanes and connectors: ' + ", ".join(f"{k} {v}" for k, v in u["lanes"].items()))
    print("tiles per split:", loc["counts"])
PY
"$exe" score -q --ground-truth "$dir/dataset" --split test --submission "$dir/prior.json" \
  --out "$dir/prior-report.json" --format md
# The figures docs/generating.md and the README quote (the whole chain is deterministic): a
# change of them fails the run.
"$py" - "$dir/dataset/manifest.json" "$dir/prior-report.json" <<'PY'
import json, sys
lanes = json.load(open(sys.argv[1]))["locations"][0]["map_update"]["lanes"]
mean = json.load(open(sys.argv[2]))["aggregate"]["mean"]
want_lanes = {"unchanged": 291, "added": 3, "removed": 16, "moved": 0, "retyped": 6}
want = {"apls": 0.962, "f1": 0.985, "topo_f1": 0.968}
bad = [f"lanes {lanes} (expected {want_lanes})"] if lanes != want_lanes else []
bad += [f"{k} {mean[k]:.4f} (expected {v} ± 0.002)" for k, v in want.items() if abs(mean[k] - v) > 0.002]
if bad:
    sys.exit("map-update: the figures docs/generating.md quotes changed: " + "; ".join(bad))
print("map-update: the quoted figures hold")
PY

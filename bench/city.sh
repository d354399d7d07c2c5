#!/usr/bin/env bash
# Memory at scale, called by scripts/bench.sh. The city world
# (samples/synth/city.json: 2.2 × 1.7 km, 160 scenes, LiDAR only) and the demo world as the
# benchmarks have always measured it (the grid, samples/synth/demo-grid.json, with
# samples/generate-demo.json: cameras on; `make demo` moved to the organic city) are synthesized (or
# reused with NSG_BENCH_REUSE=1), then `generate -v` runs on each at 1 and 2 threads under
# /usr/bin/time; bench/python/city_report.py writes city.json: LiDAR sweeps/s, peak RSS per
# thread count, bytes of peak RSS per covered LiDAR cell, the memory estimate against the
# measured peak on both worlds, and on the demo world with `camera.semantic_source: lidarseg`
# (2 threads) and with --ladder (2 threads); then `nsgraph frames` on the demo dataset (frames/s, one core, images referenced). city_report.py exits 1 when a target is missed (BENCH_REPORT_ONLY=1: never).
#   usage: bench/city.sh NSGRAPH_EXE OUT_DIR DATA_DIR
set -euo pipefail
exe=$1 out=$2 data=$3
root=$(cd "$(dirname "$0")/.." && pwd)

# synth_world NAME CONFIG: the release in $data/synth-NAME.
synth_world() {
  local name=$1 config=$2 release="$data/synth-$1"
  if [ "${NSG_BENCH_REUSE:-}" = 1 ] && ls -d "$release"/v1.0-* >/dev/null 2>&1; then
    printf '\n== synth %s: reusing %s (NSG_BENCH_REUSE=1)\n' "$name" "$release"
    [ -s "$out/synth-$name.txt" ] || echo "synth: reused" >"$out/synth-$name.txt"
  else
    printf '\n== synth %s (%s)\n' "$name" "$config"
    rm -rf "$release"
    /usr/bin/time -f 'synth: %e s wall, %M KiB peak RSS' \
      "$exe" synth --quiet --config "$config" --out "$release" 2>&1 | tee "$out/synth-$name.txt"
  fi
}

# generate_world LABEL WORLD "THREADS" [generate options...]: runs generate on the release of
# WORLD at each thread count into generate-LABEL-T.txt.
generate_world() {
  local name=$1 release="$data/synth-$2" thread_counts=$3
  shift 3
  local version
  version=$(basename "$(ls -d "$release"/v1.0-* | head -1)")
  # Both thread counts read the sweeps from the page cache: the first run would otherwise
  # time the disk (a cold city read is 5× slower than a warm one).
  find "$release/sweeps" -type f -exec cat {} + >/dev/null
  for threads in $thread_counts; do
    printf '\n== generate on the %s world, %s thread(s)\n' "$name" "$threads"
    rm -rf "$data/generate-$name"
    /usr/bin/time -f 'generate: %e s wall, %M KiB peak RSS' \
      "$exe" -v generate "$@" --dataroot "$release" --version "$version" --out "$data/generate-$name" \
      --threads "$threads" 2>&1 | grep -E '^generate|^debug: generate|peak RSS' | tee "$out/generate-$name-$threads.txt"
  done
  if [ "${FRAMES_ON:-}" = "$name" ]; then  # nsgraph frames on the last dataset, images referenced
    printf '\n== frames on the %s world (images referenced, one core)\n' "$name"
    /usr/bin/time -f 'frames: %e s wall, %M KiB peak RSS' \
      "$exe" frames --dataset "$data/generate-$name" --out "$data/frames-$name" --overwrite 2>&1 \
      | grep -E '^frames: [0-9]|peak RSS' | tee "$out/frames-$name.txt"
    rm -rf "$data/frames-$name"
  fi
  rm -rf "$data/generate-$name"
}

synth_world city "$root/samples/synth/city.json"
generate_world city city "1 2"
synth_world demo "$root/samples/synth/demo-grid.json"
FRAMES_ON=demo generate_world demo demo "1 2" --config "$root/samples/generate-demo.json"
generate_world demo-lidarseg demo "2" --config "$root/samples/generate-demo.json" \
  --set camera.semantic_source=lidarseg
# The observation ladder (rungs 1, 2, 4 of every test tile) against the plain 2-thread run.
generate_world demo-ladder demo "2" --config "$root/samples/generate-demo.json" --ladder
/usr/bin/python3 "$root/bench/python/city_report.py" --dir "$out"

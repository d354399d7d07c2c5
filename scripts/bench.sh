#!/usr/bin/env bash
# `make bench`: the speed and memory targets of DESIGN.md §8, measured on this machine.
# Each benchmark binary prints its own figures; results are collected in bench-out/.
set -euo pipefail
build=${1:-build}
root=$(cd "$(dirname "$0")/.." && pwd)
out="$root/bench-out"
mkdir -p "$out"
export NSG_BENCH_DIR="$out/data"
mkdir -p "$NSG_BENCH_DIR"

ran=0
for module in nuscenes metrics synth raster; do
  bin="$root/$build/bench/$module/bench_$module"
  [ -x "$bin" ] || continue
  printf '\n== bench_%s\n' "$module"
  "$bin" --benchmark_out="$out/bench_$module.json" --benchmark_out_format=json | tee "$out/bench_$module.txt"
  ran=$((ran + 1))
done

exe="$root/$build/tools/nsgraph/nsgraph"
if "$exe" synth --help >/dev/null 2>&1 && [ -f "$root/samples/synth/bench.json" ]; then
  printf '\n== synth bench.json (wall time, peak memory)\n'
  rm -rf "$NSG_BENCH_DIR/synth-bench"
  /usr/bin/time -f 'synth: %e s wall, %M KiB peak RSS' \
    "$exe" synth --quiet --config "$root/samples/synth/bench.json" --out "$NSG_BENCH_DIR/synth-bench" \
    2>&1 | tee "$out/synth.txt"
  ran=$((ran + 1))
fi
if "$exe" generate --help >/dev/null 2>&1 && [ -d "$NSG_BENCH_DIR/synth-bench" ]; then
  # The whole raster + tiling stage on bench.json (real-size sweeps and cameras), one
  # thread so the rates are per core; stage times come from generate's summary line.
  printf '\n== generate on bench.json (one thread: per-core rates, peak memory)\n'
  version=$(basename "$(ls -d "$NSG_BENCH_DIR"/synth-bench/v1.0-* | head -1)")
  rm -rf "$NSG_BENCH_DIR/generate-bench"
  /usr/bin/time -f 'generate: %e s wall, %M KiB peak RSS' \
    "$exe" generate --dataroot "$NSG_BENCH_DIR/synth-bench" --version "$version" \
    --out "$NSG_BENCH_DIR/generate-bench" --threads 1 --set crops.min_lidar_coverage=0.2 2>&1 \
    | grep -v '^tiles ' | tee "$out/generate.txt"
  /usr/bin/python3 - "$out/generate.txt" <<'PY'
import json, re, sys
text = open(sys.argv[1]).read()
m = re.search(r"(\d+) tiles written.*?(\d+) sweeps, (\d+) images; ([\d.]+) s \(load ([\d.]+), graph ([\d.]+), "
              r"lidar ([\d.]+), plan ([\d.]+), camera ([\d.]+), tiles ([\d.]+)", text)
rss = re.search(r"(\d+) KiB peak RSS", text)
if m:
    tiles, sweeps, images, total, load, graph, lidar, plan, camera, tile_s = map(float, m.groups())
    r = {"sweeps": sweeps, "lidar_s": lidar, "sweeps_per_s_per_core": sweeps / max(lidar, 1e-9),
         "images": images, "camera_s": camera, "images_per_s_per_core": images / max(camera, 1e-9),
         "tiles": tiles, "tiles_s": tile_s, "tiles_per_s_per_core": tiles / max(tile_s, 1e-9),
         "peak_rss_mb": int(rss.group(1)) / 1024 if rss else None}
    print(json.dumps(r, indent=1))
    json.dump(r, open(sys.argv[1].replace(".txt", ".json"), "w"), indent=1)
PY
  ran=$((ran + 1))
fi

echo
echo "$ran benchmark(s) run; results in $out"

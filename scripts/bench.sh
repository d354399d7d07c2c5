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
echo
echo "$ran benchmark(s) run; results in $out"

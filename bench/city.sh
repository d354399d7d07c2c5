#!/usr/bin/env bash
# The city world of issue 22 (samples/synth/city.json: 2.2 × 1.7 km, 160 scenes, LiDAR
# only), called by scripts/bench.sh: synthesizes it (or reuses it with NSG_BENCH_REUSE=1),
# runs `generate -v` at 1 and 2 threads under /usr/bin/time and writes city.json (via
# bench/python/city_report.py): LiDAR sweeps/s, peak RSS per thread count, bytes of peak
# RSS per covered LiDAR cell, the memory estimate against the measured peak.
#   usage: bench/city.sh NSGRAPH_EXE OUT_DIR DATA_DIR
set -euo pipefail
exe=$1 out=$2 data=$3
root=$(cd "$(dirname "$0")/.." && pwd)
release="$data/synth-city"
if [ "${NSG_BENCH_REUSE:-}" = 1 ] && ls -d "$release"/v1.0-* >/dev/null 2>&1; then
  printf '\n== synth city: reusing %s (NSG_BENCH_REUSE=1)\n' "$release"
  [ -s "$out/synth-city.txt" ] || echo "synth: reused" >"$out/synth-city.txt"
else
  printf '\n== synth city (2.2 x 1.7 km, 160 scenes, no cameras)\n'
  rm -rf "$release"
  /usr/bin/time -f 'synth: %e s wall, %M KiB peak RSS' \
    "$exe" synth --quiet --config "$root/samples/synth/city.json" --out "$release" 2>&1 | tee "$out/synth-city.txt"
fi
version=$(basename "$(ls -d "$release"/v1.0-* | head -1)")
for threads in 1 2; do
  printf '\n== generate on the city world, %s thread(s)\n' "$threads"
  rm -rf "$data/generate-city"
  /usr/bin/time -f 'generate: %e s wall, %M KiB peak RSS' \
    "$exe" -v generate --dataroot "$release" --version "$version" --out "$data/generate-city" \
    --threads "$threads" 2>&1 | grep -E '^generate|^debug: generate|peak RSS' | tee "$out/generate-city-$threads.txt"
done
rm -rf "$data/generate-city"
/usr/bin/python3 "$root/bench/python/city_report.py" --dir "$out"

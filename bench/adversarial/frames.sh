#!/usr/bin/env bash
# score --frames at its file-size limit (docs/hosting.md): a results file of 130 MB
# (make_frames_results.py, just under --max-file-mb's 128 MiB) against the golden frames,
# scored with --threads 1 under /usr/bin/time. Fails above MAX_RSS_MB (default 1536: the
# hosting recipe caps a scorer at 2 GB) or MAX_CPU_S (default 30).
#   usage: bench/adversarial/frames.sh [build-dir] [out-dir]
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-build}
out=${2:-$root/bench-out/adversarial-frames}
exe=$root/$build/tools/nsgraph/nsgraph
max_mb=${MAX_RSS_MB:-1536}
max_s=${MAX_CPU_S:-30}
mkdir -p "$out"
/usr/bin/python3 "$root/bench/adversarial/make_frames_results.py" "$out/results.json" 130
set +e
/usr/bin/time -f '%U %S %e %M' -o "$out/time.txt" "$exe" score --quiet --frames --threads 1 \
  --ground-truth "$root/tests/data/golden/frames/gt.json" --submission "$out/results.json" >"$out/report.json" \
  2>"$out/err.txt"
rc=$?
set -e
read -r user sys wall rss_kb < <(tail -1 "$out/time.txt")
cpu=$(awk -v u="$user" -v s="$sys" 'BEGIN { printf "%.2f", u + s }')
rss_mb=$((rss_kb / 1024))
verdict=ok
[ "$rc" = 0 ] || verdict="FAIL (exit $rc: $(head -c 300 "$out/err.txt"))"
[ "$rss_mb" -le "$max_mb" ] || verdict="FAIL (> $max_mb MB)"
awk -v c="$cpu" -v m="$max_s" 'BEGIN { exit !(c <= m) }' || verdict="FAIL (> $max_s s)"
printf 'score --frames at the file limit: 130 MB of results, %s s CPU (%s s wall), peak RSS %d MB  %s\n' \
  "$cpu" "$wall" "$rss_mb" "$verdict" | tee "$out/result.txt"
printf '{"cpu_seconds": %s, "wall_seconds": %s, "peak_rss_mb": %d, "ok": %s}\n' "$cpu" "$wall" "$rss_mb" \
  "$([ "$verdict" = ok ] && echo true || echo false)" >"$out/frames_limit.json"
[ "$verdict" = ok ]

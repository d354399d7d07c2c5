#!/usr/bin/env bash
# The bounded-scoring check (docs/scoring-limits.md): builds the adversarial submission at
# the per-tile limits (make_submission.py), scores it with `nsgraph score --threads 1` under
# /usr/bin/time, prints CPU seconds per tile (user + system: the machine may be shared, so
# wall time is shown but not judged) and peak RSS, and exits 1 when a tile takes more than
# MAX_S_PER_TILE (default 2) or the run more than MAX_RSS_MB (default 1024), or when the
# submission beyond the work limit is not refused (exit 1) within 10 s.
#   usage: bench/adversarial/score.sh [build-dir] [out-dir]
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-build}
out=${2:-$root/bench-out/adversarial}
exe=$root/$build/tools/nsgraph/nsgraph
max_s=${MAX_S_PER_TILE:-2}
max_mb=${MAX_RSS_MB:-1024}
mkdir -p "$out"
/usr/bin/python3 "$root/bench/adversarial/make_submission.py" "$out" | tee "$out/cases.txt"
tiles=$(grep -c . "$out/cases.txt")
/usr/bin/time -f '%U %S %e %M' -o "$out/time.txt" "$exe" score -q --threads 1 --ground-truth "$out/gt.json" \
  --submission "$out/submission.json" --format csv --out "$out/report.json" >"$out/tiles.csv"
read -r user sys wall rss_kb <"$out/time.txt"
seconds=$(awk -v u="$user" -v s="$sys" 'BEGIN { printf "%.2f", u + s }')
per_tile=$(awk -v s="$seconds" -v n="$tiles" 'BEGIN { printf "%.2f", s / n }')
rss_mb=$((rss_kb / 1024))
verdict=ok
awk -v p="$per_tile" -v m="$max_s" 'BEGIN { exit !(p <= m) }' || verdict="FAIL (> $max_s s per tile)"
[ "$rss_mb" -le "$max_mb" ] || verdict="FAIL (> $max_mb MB)"
# Beyond the limits: refused (exit 1) before scoring, quickly.
set +e
/usr/bin/time -f '%e' -o "$out/refused-time.txt" "$exe" score -q --ground-truth "$out/gt.json" \
  --submission "$out/refused.json" >/dev/null 2>"$out/refused.txt"
refused_rc=$?
set -e
refused_s=$(tail -1 "$out/refused-time.txt")
[ "$refused_rc" = 1 ] && awk -v s="$refused_s" 'BEGIN { exit !(s <= 10) }' || verdict="FAIL (not refused in 10 s)"
printf 'adversarial score: %d tiles at the limits, %s s CPU (%s s wall), %s s per tile, peak RSS %d MB; beyond the limits refused (exit %s) in %s s  %s\n' \
  "$tiles" "$seconds" "$wall" "$per_tile" "$rss_mb" "$refused_rc" "$refused_s" "$verdict" | tee "$out/result.txt"
printf '{"tiles": %d, "cpu_seconds": %s, "wall_seconds": %s, "seconds_per_tile": %s, "peak_rss_mb": %d, "refused_seconds": %s, "ok": %s}\n' \
  "$tiles" "$seconds" "$wall" "$per_tile" "$rss_mb" "$refused_s" "$([ "$verdict" = ok ] && echo true || echo false)" \
  >"$out/adversarial_score.json"
[ "$verdict" = ok ]

#!/usr/bin/env bash
# The bounded-scoring check (docs/scoring-limits.md): builds the adversarial cases at the
# per-tile limits against a connected junction (make_submission.py) and scores each alone
# with `nsgraph score --threads 1` under /usr/bin/time. Every case, scored or refused, must
# take at most MAX_S_PER_TILE (default 2) CPU seconds (user + system: the machine may be
# shared, so wall time is shown but not judged) and MAX_RSS_MB (default 1024). The copies
# and the dense lanes must be scored (exit 0); mesh and random must be refused by the
# search work limit (exit 1), and refused.json by the static limits (exit 1). values.json (a
# file near the JSON value limit, every tile extra) is judged on memory only.
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

verdict=ok
worst_s=0
worst_mb=0
rows=()
# case  expected exit
for spec in "copy 0 $max_s" "copy16 0 $max_s" "lanes 0 $max_s" "mesh 1 $max_s" "random 1 $max_s" \
  "refused 1 $max_s" "values 0 600"; do
  read -r name want case_max_s <<<"$spec"
  set +e
  /usr/bin/time -f '%U %S %e %M' -o "$out/$name.time" "$exe" -v score --threads 1 --ground-truth "$out/gt-$name.json" \
    --submission "$out/$name.json" --format csv --out "$out/$name.report.json" >"$out/$name.csv" 2>"$out/$name.err"
  rc=$?
  set -e
  read -r user sys wall rss_kb < <(tail -1 "$out/$name.time")
  seconds=$(awk -v u="$user" -v s="$sys" 'BEGIN { printf "%.2f", u + s }')
  rss_mb=$((rss_kb / 1024))
  outcome=$([ "$rc" = 0 ] && echo scored || echo "refused (exit $rc)")
  # The search work the scored tiles spent (score -v logs it per tile), and CPU per unit
  # (process start and parsing included).
  units=$({ grep -o 'search work [0-9]*' "$out/$name.err" || true; } | awk '{ s += $3 } END { print s + 0 }')
  work=""
  [ "$units" -gt 0 ] && work=$(awk -v u="$units" -v s="$seconds" \
    'BEGIN { printf "%.1f M units = %.2f of the limit, %.1f ns a unit", u / 1e6, u / 160e6, s / u * 1e9 }')
  printf '  %-8s %-18s %5s s CPU (%s s wall), %4d MB  %s\n' "$name" "$outcome" "$seconds" "$wall" "$rss_mb" "$work" |
    tee -a "$out/rows.txt"
  rows+=("{\"case\": \"$name\", \"exit\": $rc, \"cpu_seconds\": $seconds, \"wall_seconds\": $wall, \"peak_rss_mb\": $rss_mb, \"search_work\": $units}")
  [ "$rc" = "$want" ] || verdict="FAIL ($name: exit $rc, expected $want: $(grep -v '^debug' "$out/$name.err" | head -c 300))"
  awk -v p="$seconds" -v m="$case_max_s" 'BEGIN { exit !(p <= m) }' || verdict="FAIL ($name: > $case_max_s s)"
  [ "$rss_mb" -le "$max_mb" ] || verdict="FAIL ($name: > $max_mb MB)"
  [ "$name" = values ] || worst_s=$(awk -v a="$worst_s" -v b="$seconds" 'BEGIN { print (b > a ? b : a) }')
  [ "$rss_mb" -le "$worst_mb" ] || worst_mb=$rss_mb
done
printf 'adversarial score: 6 cases against a connected junction, worst %s s CPU per tile, peak RSS %d MB (a file near the value limit included)  %s\n' \
  "$worst_s" "$worst_mb" "$verdict" | tee "$out/result.txt"
{
  printf '{"worst_cpu_seconds": %s, "peak_rss_mb": %d, "ok": %s, "cases": [' "$worst_s" "$worst_mb" \
    "$([ "$verdict" = ok ] && echo true || echo false)"
  (IFS=,; printf '%s' "${rows[*]}")
  printf ']}\n'
} >"$out/adversarial_score.json"
[ "$verdict" = ok ]

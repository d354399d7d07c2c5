#!/usr/bin/env bash
# Builds the libFuzzer targets in a clang build dir and runs each for FUZZ_SECONDS (default 60;
# FUZZ_SECONDS=10 is the CI smoke run). Seeds come from a synthetic release (made once with a
# Release nsgraph, see NSG_FUZZ_RELEASE). Crashes land in <build>/fuzz-artifacts/<target>/;
# the script exits 1 if any target found one.
#   usage: scripts/fuzz.sh [build-dir]   env: FUZZ_SECONDS, FUZZ_TARGETS, JOBS, NSG_FUZZ_RELEASE, BUILD
set -euo pipefail
cd "$(dirname "$0")/.."
FUZZ_BUILD=${1:-build-fuzz}
FUZZ_SECONDS=${FUZZ_SECONDS:-60}
FUZZ_TARGETS=${FUZZ_TARGETS:-"table map pcd detections submission tar_index tile_json manifest images score receipt merge model frames frames_manifest frames_record graphify"}
JOBS=${JOBS:-2}
RELEASE_BUILD=${BUILD:-build}

launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
if [[ ! -f $FUZZ_BUILD/CMakeCache.txt ]]; then
  # -O1 with line tables only: what libFuzzer's docs advise, enough for a symbolized stack,
  # and 13 % less compile time than -O2 -g (10 library files timed; the fuzz build compiles
  # most of lib/ again).
  CC=clang CXX=clang++ cmake -S . -B "$FUZZ_BUILD" -G "Unix Makefiles" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only -DNDEBUG" \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only -DNDEBUG" -DNSG_BUILD_FUZZ=ON \
    -DNSG_BUILD_TESTS=OFF -DNSG_BUILD_BENCH=OFF "${launcher[@]}"
fi
# All targets in one build, keeping going past an error (make -k): a library that does not
# compile with this clang only loses the fuzzers that need it (reported, and the script fails
# at the end), and both cores stay busy (one target at a time left one idle most of the time:
# `make fuzz FUZZ_SECONDS=10` from an empty build folder took 20 min 20 s that way and 12 min 8 s
# this way, with -O1 and precompiled headers, on the 2-core machine; 2026-12-07).
declare -A built
targets=()
for t in $FUZZ_TARGETS; do targets+=("fuzz_$t"); done
if ! cmake --build "$FUZZ_BUILD" --target "${targets[@]}" -j "$JOBS" -- -k >"$FUZZ_BUILD/fuzz.build.log" 2>&1; then
  echo "fuzz: some targets did not build, see $FUZZ_BUILD/fuzz.build.log:" >&2
  grep -m5 'error' "$FUZZ_BUILD/fuzz.build.log" >&2 || true
fi
for t in $FUZZ_TARGETS; do
  # Built: the binary exists and make reported neither an error in it nor "not remade".
  if [[ -x $FUZZ_BUILD/fuzz/fuzz_$t ]] &&
     ! grep -Eq "fuzz_$t([^a-z_]|$).*(Error|not remade)" "$FUZZ_BUILD/fuzz.build.log"; then
    built[$t]=1
  fi
done

# The seed release and the dataset generated from it (its manifest seeds fuzz_manifest): given,
# or made once with a Release nsgraph (never the fuzz build's).
release=${NSG_FUZZ_RELEASE:-$FUZZ_BUILD/seed-release}
dataset=${NSG_FUZZ_DATASET:-$FUZZ_BUILD/seed-dataset}
exe=$RELEASE_BUILD/tools/nsgraph/nsgraph
release_nsgraph() {
  if [[ ! -x $exe ]]; then
    [[ -f $RELEASE_BUILD/CMakeCache.txt ]] || cmake -S . -B "$RELEASE_BUILD" -DCMAKE_BUILD_TYPE=Release
    cmake --build "$RELEASE_BUILD" --target nsgraph -j "$JOBS"
  fi
}
if [[ ! -f $release/v1.0-mini/sample.json ]]; then
  release_nsgraph
  rm -rf "$release.tmp"
  "$exe" synth --quiet --config tests/data/synth/e2e.json --out "$release.tmp"
  mv "$release.tmp" "$release"
fi
if [[ ! -f $dataset/manifest.json ]]; then
  release_nsgraph
  rm -rf "$dataset.tmp"
  "$exe" generate --quiet --config tests/data/generate/e2e.json --dataroot "$release" --version v1.0-mini \
    --out "$dataset.tmp" --ladder --tiles-per-shard 3
  mv "$dataset.tmp" "$dataset"
fi
seeds=$FUZZ_BUILD/fuzz-seeds
rm -rf "$seeds"
/usr/bin/python3 fuzz/make_corpus.py "$release" "$seeds" "$dataset"

status=0
printf '%-12s %8s %10s %8s %8s  %s\n' target seconds execs execs/s corpus result
for t in $FUZZ_TARGETS; do
  if [[ -z ${built[$t]:-} ]]; then
    printf '%-12s %8s %10s %8s %8s  %s\n' "$t" - - - - "NOT BUILT"
    status=1
    continue
  fi
  corpus=$FUZZ_BUILD/fuzz-corpus/$t     # grows across runs
  artifacts=$FUZZ_BUILD/fuzz-artifacts/$t
  log=$FUZZ_BUILD/fuzz-logs/$t.log
  mkdir -p "$corpus" "$artifacts" "$(dirname "$log")"
  result=ok
  # -timeout: seconds per input; the scorer's inputs are whole tiles, held to 5 s.
  timeout=10
  [[ $t == score ]] && timeout=5
  # -rss_limit_mb: the readers must stay bounded on hostile input too.
  if ! ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
       "$FUZZ_BUILD/fuzz/fuzz_$t" "$corpus" "$seeds/$t" -max_total_time="$FUZZ_SECONDS" -max_len=65536 \
       -timeout="$timeout" -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$artifacts/" >"$log" 2>&1; then
    result="CRASH (see $log, $artifacts)"
    status=1
  fi
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  printf '%-12s %8s %10s %8s %8s  %s\n' "$t" "$FUZZ_SECONDS" "${execs:-?}" "${rate:-?}" \
    "$(find "$corpus" -type f | wc -l)" "$result"
done
exit $status

#!/usr/bin/env bash
# graphify on a dataset's own ground truth (docs/graphify.md "Measured"): every test tile's
# lane graph drawn as a 7-px mask, through `nsgraph graphify` with and without the crossing
# rule (split_crossings) and `nsgraph score`; prints each tile's APLS and the table per tile
# class (with junctions: a node with 3 or more neighbours; straight: the others).
# The test GraphifyTiles.* of test_skeleton on the dataset named by NSG_GRAPHIFY_DATASET.
# usage: scripts/graphify_truth.sh DATASET [BUILD]      e.g. demo-out/dataset (make demo)
set -euo pipefail
[[ $# -ge 1 && -d "$1" ]] || { echo "usage: $0 DATASET [BUILD] (a dataset folder, e.g. demo-out/dataset)" >&2; exit 2; }
dataset=$(cd "$1" && pwd)
cd "$(dirname "$0")/.."
build="${2:-build}"
exe="$build/tests/unit/skeleton/test_skeleton"
[[ -x "$exe" ]] || { echo "$0: no $exe (cmake --build $build --target test_skeleton)" >&2; exit 2; }
NSG_GRAPHIFY_DATASET="$dataset" "$exe" --gtest_filter='GraphifyTiles.*' | grep -v '^\[' | grep -v '^Running main'

#!/usr/bin/python3
"""The table loader the way a devkit user loads it: json.load of a big sample_data-shaped
table (the same file bench_nuscenes loads), each repetition in a fresh child process so
its peak RSS (resource.getrusage ru_maxrss) measures that load alone. MB = 10^6 bytes,
as bench_nuscenes counts them. Writes a JSON with every figure and its unit.
"""
import argparse
import json
import os
import re
import subprocess
import sys

# Runs in the child: the interpreter's own peak RSS before the load, then the load.
CHILD = r"""
import json, resource, sys, time
before_kib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
wall0, cpu0 = time.perf_counter(), time.process_time()
with open(sys.argv[1], "rb") as f:
    table = json.load(f)
wall, cpu = time.perf_counter() - wall0, time.process_time() - cpu0
peak_kib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print(json.dumps({"records": len(table), "wall_s": wall, "cpu_s": cpu,
                  "rss_before_kib": before_kib, "peak_rss_kib": peak_kib}))
"""


def nsgraph_figures(text_file):
    """bench_nuscenes' summary line: best MB/s wall and per CPU second, worst peak/file."""
    with open(text_file) as f:
        text = f.read()
    m = re.search(r"best (\d+) MB/s wall, (\d+) MB/s per CPU second .*?worst peak/file ([\d.]+)", text)
    path = re.search(r"sample_data-shaped table ([\d.]+) MB at (\S+)", text)
    if not m or not path:
        sys.exit(f"table_baseline: {text_file}: no bench_nuscenes summary line")
    return {"mb_per_s": float(m.group(1)), "mb_per_cpu_s": float(m.group(2)),
            "peak_rss_over_file": float(m.group(3)), "table": path.group(2)}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--table", help="the JSON table (default: the one named in --nsgraph-text)")
    ap.add_argument("--nsgraph-text", help="bench_nuscenes.txt of the same run (its figures and table path)")
    ap.add_argument("--repeat", type=int, default=2, help="loads, each in a fresh child; the fastest counts")
    ap.add_argument("--out", required=True, help="JSON result file")
    a = ap.parse_args()
    ns = nsgraph_figures(a.nsgraph_text) if a.nsgraph_text else None
    table = a.table or (ns and ns["table"])
    if not table or not os.path.isfile(table):
        sys.exit(f"table_baseline: table file '{table}' not found (bench_nuscenes with NSG_BENCH_KEEP=1 keeps it)")
    size_mb = os.path.getsize(table) / 1e6
    runs = []
    for _ in range(max(a.repeat, 1)):
        child = subprocess.run([sys.executable, "-c", CHILD, table], capture_output=True, text=True)
        if child.returncode != 0:
            sys.exit(f"table_baseline: json.load of {table} failed: {child.stderr.strip()}")
        runs.append(json.loads(child.stdout))
    best = min(runs, key=lambda r: r["wall_s"])
    result = {
        "benchmark": "tables_python_json_load",
        "python": sys.version.split()[0],
        "table_mb": size_mb,
        "records": best["records"],
        "repeats": len(runs),
        "wall_s": best["wall_s"],
        "cpu_s": best["cpu_s"],
        # json.load runs on one thread: its CPU time is its wall time on an idle machine, so
        # the faster of the two counts (a busy shared machine never flatters nsgraph).
        "mb_per_s": size_mb / min(best["wall_s"], best["cpu_s"]),
        "mb_per_s_wall": size_mb / best["wall_s"],
        "mb_per_cpu_s": size_mb / best["cpu_s"],
        "peak_rss_mb": max(r["peak_rss_kib"] for r in runs) * 1024 / 1e6,
        "peak_rss_over_file": max(r["peak_rss_kib"] for r in runs) * 1024 / 1e6 / size_mb,
    }
    if ns:
        result["nsgraph_mb_per_s"] = ns["mb_per_s"]
        result["nsgraph_mb_per_cpu_s"] = ns["mb_per_cpu_s"]
        result["nsgraph_peak_rss_over_file"] = ns["peak_rss_over_file"]
        # Both sides: the faster of wall and CPU figures (see lidar_baseline.py).
        result["nsgraph_best_mb_per_s"] = max(ns["mb_per_s"], ns["mb_per_cpu_s"])
        result["ratio_nsgraph_over_python"] = result["nsgraph_best_mb_per_s"] / result["mb_per_s"]
        result["ratio_per_cpu_s"] = ns["mb_per_cpu_s"] / result["mb_per_cpu_s"]
    with open(a.out, "w") as f:
        json.dump(result, f, indent=1)
    print(json.dumps(result, indent=1))


if __name__ == "__main__":
    main()

"""Figures of the city and demo world runs (bench/city.sh) for bench.json and bench.md.

Exits 1 when a target is missed (the figures are written first), unless --report-only or
BENCH_REPORT_ONLY=1.
"""
import argparse
import json
import os
import re
import sys

RSS_THREAD_LIMIT = 1.1      # peak at 2 threads / peak at 1 thread
BYTES_PER_CELL_LIMIT = 60   # peak RSS per covered LiDAR cell, 1 thread
ESTIMATE_TOLERANCE = 0.25   # |estimate / peak - 1|
SWEEPS_TARGET = 3000        # per core (on bench.json; reported here for the city too)
FRAMES_PER_S_TARGET = 500   # nsgraph frames, one core, images referenced (docs/frames.md)
LADDER_RSS_LIMIT = 1.1      # peak of generate --ladder / peak of the same run without, 2 threads

def parse(path):
    text = open(path).read()
    run = re.search(r"(\d+) sweeps, (\d+) images; ([\d.]+) s \(load [\d.]+, graph [\d.]+, lidar ([\d.]+), plan "
                    r"[\d.]+, camera ([\d.]+), tiles ([\d.]+)", text)
    rss = re.search(r"generate: ([\d.]+) s wall, (\d+) KiB peak RSS", text)
    est = re.search(r"estimated peak memory in bytes: (\d+)", text)
    cells = re.search(r"LiDAR accumulated: (\d+) blocks, (\d+) covered cells", text)
    if not (run and rss and est and cells):
        raise SystemExit(f"city_report: {path}: missing generate summary, time, estimate or memory lines")
    peak = int(rss.group(2)) * 1024
    return {"sweeps": int(run.group(1)), "lidar_s": float(run.group(4)),
            "sweeps_per_s": int(run.group(1)) / max(float(run.group(4)), 1e-9), "camera_s": float(run.group(5)),
            "wall_s": float(rss.group(1)), "peak_rss_bytes": peak, "estimate_bytes": int(est.group(1)),
            "estimate_over_peak": int(est.group(1)) / peak, "lidar_blocks": int(cells.group(1)),
            "covered_cells": int(cells.group(2)), "peak_bytes_per_covered_cell": peak / int(cells.group(2))}


def parse_ladder(path, plain):
    """generate --ladder against the plain run: its rung work in sweeps, wall time and memory.
    Target: the extra wall time is at most the plain run's times the extra sweeps read (the
    rungs cost no more than their own LiDAR and camera work), the peak at most 1.1x."""
    text = open(path).read()
    m = re.search(r"generate: ladder: (\d+) rung tiles from (\d+) scene lists read (\d+) sweeps \(([\d.]+)× the "
                  r"(\d+) of the all-scenes pass\) and (\d+) images", text)
    if not m:
        raise SystemExit(f"city_report: {path}: missing the generate: ladder line")
    run = parse(path)
    factor = float(m.group(4))
    return {"rung_tiles": int(m.group(1)), "scene_lists": int(m.group(2)), "rung_sweeps": int(m.group(3)),
            "sweep_factor": factor, "rung_images": int(m.group(6)), "wall_s": run["wall_s"],
            "plain_wall_s": plain["wall_s"], "wall_factor": run["wall_s"] / plain["wall_s"],
            "wall_limit": 1 + factor, "peak_rss_bytes": run["peak_rss_bytes"],
            "peak_ratio": run["peak_rss_bytes"] / plain["peak_rss_bytes"], "peak_limit": LADDER_RSS_LIMIT}


def parse_frames(path):
    text = open(path).read()
    run = re.search(r"frames: (\d+) frames \((\d+) key frames in the release\), (\d+) centerlines, (\d+) links; "
                    r"([\d.]+) s", text)
    rss = re.search(r"frames: ([\d.]+) s wall, (\d+) KiB peak RSS", text)
    if not (run and rss):
        raise SystemExit(f"city_report: {path}: missing the frames summary or time lines")
    frames, seconds = int(run.group(1)), float(run.group(5))
    return {"frames": frames, "key_frames": int(run.group(2)), "centerlines": int(run.group(3)),
            "records_s": seconds, "frames_per_s": frames / max(seconds, 1e-9), "wall_s": float(rss.group(1)),
            "peak_rss_bytes": int(rss.group(2)) * 1024, "target_frames_per_s": FRAMES_PER_S_TARGET}


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--dir", required=True)
    ap.add_argument("--report-only", action="store_true", help="exit 0 whatever the verdicts")
    a = ap.parse_args()
    one, two = (parse(os.path.join(a.dir, f"generate-city-{t}.txt")) for t in (1, 2))
    r = {"threads_1": one, "threads_2": two,
         "peak_ratio_2_over_1": two["peak_rss_bytes"] / one["peak_rss_bytes"], "limit_ratio": RSS_THREAD_LIMIT,
         "bytes_per_cell_limit": BYTES_PER_CELL_LIMIT, "estimate_tolerance": ESTIMATE_TOLERANCE}
    checked = [one, two]
    demo_files = [os.path.join(a.dir, f"generate-demo-{t}.txt") for t in (1, 2)]
    if all(os.path.exists(f) for f in demo_files):  # the demo world (cameras on): the estimate only
        r["demo"] = {f"threads_{t}": parse(f) for t, f in zip((1, 2), demo_files)}
        checked += r["demo"].values()
    lidarseg = os.path.join(a.dir, "generate-demo-lidarseg-2.txt")
    if os.path.exists(lidarseg):  # the demo world with camera.semantic_source: lidarseg, 2 threads
        r["demo_lidarseg"] = {"threads_2": parse(lidarseg)}
        checked += r["demo_lidarseg"].values()
    ladder = os.path.join(a.dir, "generate-demo-ladder-2.txt")
    if os.path.exists(ladder) and "demo" in r:
        r["demo_ladder"] = parse_ladder(ladder, r["demo"]["threads_2"])
    frames_file = os.path.join(a.dir, "frames-demo.txt")
    if os.path.exists(frames_file):
        r["frames_demo"] = parse_frames(frames_file)
    r["pass"] = {"threads": r["peak_ratio_2_over_1"] <= RSS_THREAD_LIMIT,
                 "bytes_per_cell": one["peak_bytes_per_covered_cell"] <= BYTES_PER_CELL_LIMIT,
                 "estimate": all(abs(x["estimate_over_peak"] - 1) <= ESTIMATE_TOLERANCE for x in checked)}
    if "demo_ladder" in r:
        d = r["demo_ladder"]
        r["pass"]["ladder_wall"] = d["wall_factor"] <= d["wall_limit"]
        r["pass"]["ladder_memory"] = d["peak_ratio"] <= d["peak_limit"]
    if "frames_demo" in r:
        r["pass"]["frames_per_s"] = r["frames_demo"]["frames_per_s"] >= FRAMES_PER_S_TARGET
    json.dump(r, open(os.path.join(a.dir, "city.json"), "w"), indent=1)
    print(json.dumps(r, indent=1))
    missed = [k for k, ok in r["pass"].items() if not ok]
    if missed:
        print(f"city_report: target(s) missed: {', '.join(missed)}", file=sys.stderr)
        if not (a.report_only or os.environ.get("BENCH_REPORT_ONLY") == "1"):
            sys.exit(1)


if __name__ == "__main__":
    main()

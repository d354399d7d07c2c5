#!/usr/bin/python3
"""Collects the per-benchmark files of a `make bench` run (bench-out/) into bench.json
(the machine and every figure, with units in the key names) and bench.md (the table docs/benchmarks.md
shows). Missing pieces are reported as missing, never guessed.

Every target gets a verdict (bench.json's "verdicts"); the exit status is 1 when one is
missed, unless --report-only or BENCH_REPORT_ONLY=1. A verdict's kind says how robust it is
on a shared machine: "ratio" compares two measurements of the same run (nsgraph against the
Python way on the same data, one peak against another, an estimate against its measured
peak), so machine load affects both sides; "absolute" compares a rate with a fixed number and
depends on the machine and its load; "memory" compares bytes with a fixed number (the
machine's speed does not matter).
"""
import argparse
import datetime
import json
import os
import platform
import re
import sys

LIDAR_TARGET = 10.0   # nsgraph / Python
TABLE_TARGET = 4.0
CANVAS_LIMIT = 1.1    # peak RSS 4x canvas / 1x canvas
TABLE_RSS_LIMIT = 2.0  # table load peak RSS / file size
SWEEPS_TARGET = 3000   # LiDAR stage of `generate --threads 1` on bench.json, sweeps/s


def read_json(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def read_text(path):
    try:
        with open(path) as f:
            return f.read()
    except OSError:
        return None


def machine():
    cpu = None
    text = read_text("/proc/cpuinfo") or ""
    m = re.search(r"^model name\s*:\s*(.+)$", text, re.M)
    if m:
        cpu = m.group(1).strip()
    mem = re.search(r"^MemTotal:\s*(\d+) kB", read_text("/proc/meminfo") or "", re.M)
    return {
        "cpu_model": cpu or platform.processor() or platform.machine(),
        "logical_cores": os.cpu_count(),
        "ram_gib": round(int(mem.group(1)) / 2**20, 1) if mem else None,
        "kernel": f"{platform.system()} {platform.release()}",
        "os": (re.search(r'^PRETTY_NAME="?([^"\n]+)', read_text("/etc/os-release") or "", re.M) or [None, None])[1],
        "python": platform.python_version(),
        "date_utc": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
    }


def time_rss(text, tool):
    """The /usr/bin/time line of `tool` in a log: (wall s, peak RSS MB)."""
    m = re.search(rf"{tool}: ([\d.]+) s wall, (\d+) KiB peak RSS", text or "")
    return (float(m.group(1)), int(m.group(2)) / 1024) if m else (None, None)


def table_loader(text):
    if not text:
        return None
    m = re.search(r"best (\d+) MB/s wall, (\d+) MB/s per CPU second .*?worst peak/file ([\d.]+)", text)
    size = re.search(r"sample_data-shaped table ([\d.]+) MB", text)
    if not m:
        return None
    return {"table_mb": float(size.group(1)) if size else None, "mb_per_s": float(m.group(1)),
            "mb_per_cpu_s": float(m.group(2)), "peak_rss_over_file": float(m.group(3))}


def table_scale(text):
    """bench_nuscenes' scale case (NSG_BENCH_SCALE_MB): size, records, rate, peak RSS / file, verdict."""
    if not text:
        return None
    if "SKIP" in text:
        return {"skipped": text.strip()}
    size = re.search(r"table ([\d.]+) MB \((\d+) records", text)
    load = re.search(r"loaded (\d+) records in ([\d.]+) s = (\d+) MB/s \(CPU ([\d.]+) s = (\d+) MB/s\); "
                     r"peak RSS ([\d.]+) MB = ([\d.]+)x file", text)
    if not size or not load:
        return {"failed": text.strip()[-500:]}
    return {"table_mb": float(size.group(1)), "records_written": int(size.group(2)), "records_read": int(load.group(1)),
            "load_s": float(load.group(2)), "mb_per_s": float(load.group(3)), "mb_per_cpu_s": float(load.group(5)),
            "peak_rss_mb": float(load.group(6)), "peak_rss_over_file": float(load.group(7)), "limit_over_file": 1.0,
            "pass": "PASS" in text and "FAIL" not in text}


def google_benchmarks(path):
    doc = read_json(path)
    if not doc:
        return None
    keep = ("real_time", "cpu_time", "time_unit", "items_per_second")
    out = {}
    for b in doc.get("benchmarks", []):
        out[b["name"]] = {k: b[k] for k in b if k in keep or k not in (
            "name", "family_index", "per_family_instance_index", "run_name", "run_type", "repetitions",
            "repetition_index", "threads", "iterations", "aggregate_name", "aggregate_unit")}
    return out


def verdict(ok):
    return "n/a" if ok is None else ("pass" if ok else "FAIL")


def fmt(x, spec, unit=""):
    return "n/a" if x is None else f"{x:{spec}}{unit}"


def load_average(d, when):
    text = read_text(os.path.join(d, f"loadavg-{when}.txt"))
    return float(text.split()[0]) if text else None


def lidar_ratio_range(gen, lidar):
    """generate prints stage seconds rounded (to 1 ms): the ratio's bounds from that rounding."""
    if not gen or not lidar or not gen.get("stage_s_rounding") or not (lidar.get("nsgraph_figure") or "").startswith(
            "generate"):
        return None
    half, s = gen["stage_s_rounding"] / 2, gen["lidar_s"]
    py = lidar["sweeps_per_s"]
    low = gen["sweeps"] / (s + half) / py
    return [low, gen["sweeps"] / (s - half) / py if s > half else None]


def collect(d):
    gen = read_json(os.path.join(d, "generate-bench.json"))
    lidar = read_json(os.path.join(d, "lidar_python.json"))
    tables = read_json(os.path.join(d, "tables_python.json"))
    synth_wall, synth_rss = time_rss(read_text(os.path.join(d, "synth-bench.txt")), "synth")
    canvas = {}
    for c in ("1", "4"):
        g = read_json(os.path.join(d, f"generate-canvas{c}.json"))
        s_wall, s_rss = time_rss(read_text(os.path.join(d, f"synth-canvas{c}.txt")), "synth")
        canvas[c] = {"synth_wall_s": s_wall, "synth_peak_rss_mb": s_rss,
                     "generate_peak_rss_mb": g and g.get("peak_rss_mb"), "generate_wall_s": g and g.get("wall_s"),
                     "sweeps": g and g.get("sweeps"), "tiles": g and g.get("tiles"),
                     "covered_lidar_cells": (read_json(os.path.join(d, f"canvas{c}-coverage.json")) or {}).get(
                         "covered_cells")}

    def ratio(key):
        a, b = canvas["4"][key], canvas["1"][key]
        return a / b if a and b else None

    memory = {"canvas_1x": canvas["1"], "canvas_4x": canvas["4"],
              "same_sweeps": canvas["1"]["sweeps"] == canvas["4"]["sweeps"] if canvas["1"]["sweeps"] else None,
              "same_covered_cells": (canvas["1"]["covered_lidar_cells"] == canvas["4"]["covered_lidar_cells"]
                                     if canvas["1"]["covered_lidar_cells"] else None),
              "generate_peak_rss_ratio_4x_over_1x": ratio("generate_peak_rss_mb"),
              "synth_peak_rss_ratio_4x_over_1x": ratio("synth_peak_rss_mb"), "limit_ratio": CANVAS_LIMIT}
    mach = machine()
    mach["load_average_1min_start"] = load_average(d, "start")
    mach["load_average_1min_end"] = load_average(d, "end")
    return {
        "machine": mach,
        "generate_bench": dict(gen or {}, synth_wall_s=synth_wall, synth_peak_rss_mb=synth_rss) if gen else None,
        "lidar": {"nsgraph_sweeps_per_s_per_core": lidar and lidar.get("nsgraph_sweeps_per_s"),
                  "nsgraph_figure": lidar and lidar.get("nsgraph_figure"),
                  "python": lidar, "target_ratio": LIDAR_TARGET,
                  "ratio_nsgraph_over_python": lidar and lidar.get("ratio_nsgraph_over_python"),
                  "ratio_bounds_from_stage_rounding": lidar_ratio_range(gen, lidar)},
        "tables": {"nsgraph": table_loader(read_text(os.path.join(d, "bench_nuscenes.txt"))), "python": tables,
                   "target_ratio": TABLE_TARGET,
                   "ratio_nsgraph_over_python": tables and tables.get("ratio_nsgraph_over_python"),
                   "scale": table_scale(read_text(os.path.join(d, "tables_scale.txt")))},
        "memory_vs_canvas": memory,
        "city": read_json(os.path.join(d, "city.json")),
        "dataset_read": read_json(os.path.join(d, "dataset_read.json")),
        "adversarial_score": read_json(os.path.join(d, "adversarial_score.json")),
        "google_benchmarks": {m: google_benchmarks(os.path.join(d, f"bench_{m}.json"))
                              for m in ("metrics", "synth", "raster")
                              if os.path.exists(os.path.join(d, f"bench_{m}.json"))},
    }


def verdicts(r):
    """Each target of the report: name, kind (ratio / absolute / memory), value, target, ok (None: not run)."""
    out = []

    def add(name, kind, value, target, ok):
        out.append({"name": name, "kind": kind, "value": value, "target": target, "ok": ok})

    li, lp = r["lidar"], r["lidar"]["python"] or {}
    lr = li["ratio_nsgraph_over_python"]
    agree = (lp.get("check") or {}).get("agree")
    add("LiDAR layer nsgraph / numpy, same sweeps, layers agree", "ratio", lr, f">= {LIDAR_TARGET:g}x",
        None if lr is None else (lr >= LIDAR_TARGET and bool(agree) and bool(lp.get("same_sweeps"))))
    tr = r["tables"]["ratio_nsgraph_over_python"]
    add("JSON table load nsgraph / json.load", "ratio", tr, f">= {TABLE_TARGET:g}x",
        None if tr is None else tr >= TABLE_TARGET)
    tnr = (r["tables"]["nsgraph"] or {}).get("peak_rss_over_file")
    add("table load peak RSS / file size", "ratio", tnr, f"<= {TABLE_RSS_LIMIT:g}x",
        None if tnr is None else tnr <= TABLE_RSS_LIMIT)
    sc = r["tables"].get("scale")
    if sc and "skipped" not in sc:
        add("table load at scale: all records, peak RSS / file", "ratio", sc.get("peak_rss_over_file"),
            "<= 1x, every record", bool(sc.get("pass")))
    g = r.get("generate_bench")
    sweeps = g and g.get("sweeps_per_s_per_core")
    add("generate LiDAR stage on bench.json, 1 thread, sweeps/s", "absolute", sweeps, f">= {SWEEPS_TARGET}",
        None if sweeps is None else sweeps >= SWEEPS_TARGET)
    dr = r.get("dataset_read")
    if dr:
        add("nsgraph.Dataset tiles/s, 1 core, arrays equal", "absolute", dr["nsgraph_tiles_per_s"],
            f">= {dr['target_tiles_per_s']}", bool(dr["arrays_equal"]) and dr["nsgraph_tiles_per_s"] >= dr["target_tiles_per_s"])
    mem = r["memory_vs_canvas"]
    for tool in ("generate", "synth"):
        ratio = mem[f"{tool}_peak_rss_ratio_4x_over_1x"]
        add(f"{tool} peak RSS 4x canvas / 1x canvas", "ratio", ratio, f"<= {CANVAS_LIMIT:g}x",
            None if ratio is None else ratio <= CANVAS_LIMIT and mem["same_covered_cells"] is not False)
    city = r.get("city")
    if city:
        ok = city["pass"]
        add("city world peak RSS 2 threads / 1 thread", "ratio", city["peak_ratio_2_over_1"],
            f"<= {city['limit_ratio']:g}x", ok["threads"])
        add("city world peak RSS per covered LiDAR cell, 1 thread, bytes", "memory",
            city["threads_1"]["peak_bytes_per_covered_cell"], f"<= {city['bytes_per_cell_limit']}", ok["bytes_per_cell"])
        tol = city["estimate_tolerance"]
        for world, runs in [("city", city)] + [(w, city[w]) for w in ("demo", "demo_lidarseg") if city.get(w)]:
            for key, run in sorted(runs.items()):
                if not key.startswith("threads_"):
                    continue
                e = run["estimate_over_peak"]
                add(f"{world} world memory estimate / peak, {key.split('_')[1]} thread(s)", "ratio", e,
                    f"within +-{tol:.0%}", abs(e - 1) <= tol)
        dg = city.get("demo_ladder")
        if dg:
            add("demo world generate --ladder wall time / plain run, 2 threads", "ratio", dg["wall_factor"],
                f"<= 1 + rung sweeps / all-scenes sweeps ({dg['wall_limit']:.2f})", ok["ladder_wall"])
            add("demo world generate --ladder peak RSS / plain run, 2 threads", "ratio", dg["peak_ratio"],
                f"<= {dg['peak_limit']:g}x", ok["ladder_memory"])
    return out


def markdown(r):
    m = r["machine"]
    lines = [f"Measured {m['date_utc']} on {m['cpu_model']}, {m['logical_cores']} logical cores, "
             f"{m['ram_gib']} GiB RAM, {m['kernel']} ({m['os']}); load average {fmt(m['load_average_1min_start'], '.1f')} "
             f"at the start (shared machine); Python {m['python']}"
             + (f", numpy {r['lidar']['python']['numpy_version']}" if r["lidar"]["python"] else "") + ".", "",
             "| hot path | nsgraph | Python | ratio | target | result |", "| --- | --- | --- | --- | --- | --- |"]
    li, lp = r["lidar"], r["lidar"]["python"] or {}
    lr = li["ratio_nsgraph_over_python"]
    check = lp.get("check") or {}
    agree = check.get("agree")
    lidar_ok = None if lr is None else (lr >= LIDAR_TARGET and bool(agree) and bool(lp.get("same_sweeps")))
    b = li["ratio_bounds_from_stage_rounding"]
    bounds = f" ({b[0]:.1f}–{fmt(b[1], '.1f')}×)" if b else ""
    lines.append(f"| LiDAR read + transform + lowest-z bin, {fmt(lp.get('sweeps'), '.0f')} sweeps, 1 core "
                 f"| {fmt(li['nsgraph_sweeps_per_s_per_core'], ',.0f', ' sweeps/s')}¹ "
                 f"| {fmt(lp.get('sweeps_per_s'), ',.0f', ' sweeps/s')}¹ | {fmt(lr, '.1f', '×')}{bounds} "
                 f"| ≥ {LIDAR_TARGET:.0f}× | {verdict(lidar_ok)} |")
    ec = lp.get("nsgraph_export_cloud_one_thread")
    if ec:
        lines.append(f"| same: wall / per CPU second (nsgraph wall: `generate`'s lidar stage; CPU: whole "
                     f"`export-cloud --threads 1` runs, tables and PCD write included) "
                     f"| {fmt(lp.get('nsgraph_generate_sweeps_per_s'), ',.0f')} / "
                     f"{fmt(ec['sweeps_per_cpu_s'], ',.0f', ' sweeps/s')} "
                     f"| {fmt(lp.get('sweeps_per_s_wall'), ',.0f')} / {fmt(lp.get('sweeps_per_cpu_s'), ',.0f', ' sweeps/s')} "
                     f"| – / {fmt(lp.get('ratio_per_cpu_s_export_cloud'), '.1f', '×')} | (info) | |")
    tn, tp = r["tables"]["nsgraph"] or {}, r["tables"]["python"] or {}
    tr = r["tables"]["ratio_nsgraph_over_python"]
    lines.append(f"| JSON table load, {fmt(tp.get('table_mb'), '.0f', ' MB')} sample_data "
                 f"| {fmt(tp.get('nsgraph_best_mb_per_s'), ',.0f', ' MB/s')}¹ | {fmt(tp.get('mb_per_s'), ',.0f', ' MB/s')}¹ "
                 f"| {fmt(tr, '.1f', '×')} | ≥ {TABLE_TARGET:.0f}× | {verdict(None if tr is None else tr >= TABLE_TARGET)} |")
    rc = tp.get("ratio_per_cpu_s")
    lines.append(f"| same: wall / per CPU second (nsgraph's loader uses more than one thread) "
                 f"| {fmt(tn.get('mb_per_s'), ',.0f')} / {fmt(tn.get('mb_per_cpu_s'), ',.0f', ' MB/s')} "
                 f"| {fmt(tp.get('mb_per_s_wall'), ',.0f')} / {fmt(tp.get('mb_per_cpu_s'), ',.0f', ' MB/s')} "
                 f"| – / {fmt(rc, '.1f', '×')} | (info) | |")
    tnr, tpr = tn.get("peak_rss_over_file"), tp.get("peak_rss_over_file")
    lines.append(f"| table load peak RSS / file size | {fmt(tnr, '.2f', '×')} | {fmt(tpr, '.2f', '×')} "
                 f"| | ≤ 2× (nsgraph) | {verdict(None if tnr is None else tnr <= 2.0)} |")
    sc = r["tables"].get("scale")
    if sc and "table_mb" in sc:
        lines.append(f"| table load at scale, {sc['table_mb']:,.0f} MB sample_data ({sc['records_read']:,} of "
                     f"{sc['records_written']:,} records), one load | {sc['mb_per_s']:,.0f} MB/s, peak RSS "
                     f"{sc['peak_rss_over_file']:.2f}× file | | | ≤ 1× file, all records | {verdict(sc['pass'])} |")
    elif sc:
        lines.append(f"| table load at scale | {sc.get('skipped') or 'FAILED to run'} | | | ≤ 1× file | "
                     f"{'n/a' if 'skipped' in sc else 'FAIL'} |")
    dr = r.get("dataset_read")
    if dr:
        ok = dr["arrays_equal"] and dr["nsgraph_tiles_per_s"] >= dr["target_tiles_per_s"]
        lines.append(f"| Python: read {dr['tiles']} tiles ({dr['tile_px']} px, 5 layers + graph + meta) from one shard, "
                     f"1 core | `nsgraph.Dataset` {dr['nsgraph_tiles_per_s']:,.0f} tiles/s¹ "
                     f"| tarfile + PIL {dr['python_tiles_per_s']:,.0f} tiles/s¹ | {dr['ratio_nsgraph_over_python']:.1f}× "
                     f"| ≥ {dr['target_tiles_per_s']} tiles/s | {verdict(ok)} |")
    mem = r["memory_vs_canvas"]
    for tool in ("generate", "synth"):
        ratio = mem[f"{tool}_peak_rss_ratio_4x_over_1x"]
        one, four = mem["canvas_1x"][f"{tool}_peak_rss_mb"], mem["canvas_4x"][f"{tool}_peak_rss_mb"]
        lines.append(f"| `{tool}` peak RSS, 4× map canvas vs 1× (same covered area) "
                     f"| {fmt(four, '.0f', ' MB')} vs {fmt(one, '.0f', ' MB')} | | {fmt(ratio, '.2f', '×')} "
                     f"| ≤ {CANVAS_LIMIT}× | {verdict(None if ratio is None else ratio <= CANVAS_LIMIT)} |")
    city = r.get("city")
    if city:
        one, two, ok = city["threads_1"], city["threads_2"], city["pass"]
        lines.append(f"| city world (2.2 × 1.7 km, {one['sweeps']:,} sweeps, {one['covered_cells']:,} covered cells): "
                     f"peak RSS 2 threads / 1 thread | {two['peak_rss_bytes'] / 1e6:,.0f} MB / "
                     f"{one['peak_rss_bytes'] / 1e6:,.0f} MB | | {city['peak_ratio_2_over_1']:.2f}× "
                     f"| ≤ {city['limit_ratio']}× | {verdict(ok['threads'])} |")
        lines.append(f"| city world: peak RSS per covered LiDAR cell, 1 thread | "
                     f"{one['peak_bytes_per_covered_cell']:.0f} B | | | ≤ {city['bytes_per_cell_limit']} B "
                     f"| {verdict(ok['bytes_per_cell'])} |")
        lines.append(f"| city world: `generate`'s memory estimate / measured peak, 1 and 2 threads | "
                     f"{one['estimate_over_peak']:.2f}× / {two['estimate_over_peak']:.2f}× | | | "
                     f"within ±{city['estimate_tolerance']:.0%} | {verdict(ok['estimate'])} |")
        demo = city.get("demo")
        if demo:
            lines.append(f"| demo world (cameras on): `generate`'s memory estimate / measured peak, 1 and 2 threads | "
                         f"{demo['threads_1']['estimate_over_peak']:.2f}× / {demo['threads_2']['estimate_over_peak']:.2f}× "
                         f"({demo['threads_1']['peak_rss_bytes'] / 1e6:,.0f} MB at 1 thread) | | | "
                         f"within ±{city['estimate_tolerance']:.0%} | {verdict(ok['estimate'])} |")
        dl = city.get("demo_lidarseg")
        if dl:
            lines.append(f"| demo world, `camera.semantic_source: lidarseg`: `generate`'s memory estimate / measured "
                         f"peak, 2 threads | {dl['threads_2']['estimate_over_peak']:.2f}× | | | "
                         f"within ±{city['estimate_tolerance']:.0%} | "
                         f"{verdict(abs(dl['threads_2']['estimate_over_peak'] - 1) <= city['estimate_tolerance'])} |")
        dg = city.get("demo_ladder")
        if dg:
            lines.append(f"| demo world, `generate --ladder` (rungs 1, 2, 4 of {dg['rung_tiles'] // 3} test tiles: "
                         f"{dg['rung_tiles']} rung tiles from {dg['scene_lists']} scene lists): wall time / plain run, "
                         f"2 threads | {dg['wall_s']:.1f} s / {dg['plain_wall_s']:.1f} s | | {dg['wall_factor']:.2f}× "
                         f"| ≤ 1 + {dg['sweep_factor']:.2f} (the rungs' sweeps / the all-scenes pass) "
                         f"| {verdict(ok['ladder_wall'])} |")
            lines.append(f"| demo world, `generate --ladder`: peak RSS / plain run, 2 threads | "
                         f"{dg['peak_rss_bytes'] / 1e6:,.0f} MB | | {dg['peak_ratio']:.2f}× | ≤ {dg['peak_limit']}× "
                         f"| {verdict(ok['ladder_memory'])} |")
        lines.append(f"| city world: LiDAR stage, 1 thread | {one['sweeps_per_s']:,.0f} sweeps/s | | | (info) | |")
    lines.append("")
    lines.append("Verdicts (kind: ratio = two measurements of the same run; absolute = a rate against a fixed number, "
                 "depends on the machine and its load; memory = bytes against a fixed number):")
    for v in r["verdicts"]:
        value = "n/a" if v["value"] is None else f"{v['value']:.3g}"
        lines.append(f"- {verdict(v['ok'])} [{v['kind']}] {v['name']}: {value} (target {v['target']})")
    lines.append("")
    lines.append("¹ Best of several runs; each side counts the faster of its wall-time and CPU-time rate, "
                 "because the machine is shared and a busy moment slows whichever side runs then. "
                 f"nsgraph LiDAR figure used: {li.get('nsgraph_figure') or 'n/a'} (generate: best of 3 runs).")
    cells = mem["canvas_1x"]["covered_lidar_cells"], mem["canvas_4x"]["covered_lidar_cells"]
    if cells[0]:
        lines.append(f"Canvas runs: {mem['canvas_1x']['sweeps']:.0f} sweeps each, covered LiDAR cells "
                     f"{cells[0]:,} (1×) and {cells[1]:,} (4×)"
                     f"{'' if mem['same_covered_cells'] else ' — the covered area DIFFERS'}.")
    if check:
        lines.append(f"The Python baseline computes the same layer: {check['python_covered_cells']:,} covered cells "
                     f"(nsgraph {check['nsgraph_covered_cells']:,}; {check['cells_only_python']} / "
                     f"{check['cells_only_nsgraph']} cells only in one), max |Δz| {check['max_abs_dz_m']:.2g} m, "
                     f"{check['cells_z_bit_equal']:,} cells bit-equal, z checksum {check['python_z_checksum_m']:.6f} "
                     f"vs {check['nsgraph_z_checksum_m']:.6f} m — {'agree' if agree else 'DISAGREE'}"
                     f"{' (sweep counts differ!)' if lp.get('same_sweeps') is False else ''}.")
    if b:
        lines.append(f"The LiDAR ratio's bounds come from `generate` printing stage times rounded to "
                     f"{r['generate_bench']['stage_s_rounding']:g} s.")
    g = r["generate_bench"]
    if g:
        lines.append(f"End to end (`generate --threads 1` on samples/synth/bench.json): {g['wall_s']:.1f} s wall, "
                     f"peak RSS {g['peak_rss_mb']:.0f} MB; LiDAR {g['sweeps']:.0f} sweeps in {g['lidar_s']:.2f} s, "
                     f"camera {g['images']:.0f} images at {g['images_per_s_per_core']:.1f} images/s, "
                     f"{g['tiles']:.0f} tiles at {g['tiles_per_s_per_core']:.1f} tiles/s"
                     + (f"; synth {g['synth_wall_s']:.0f} s, {g['synth_peak_rss_mb']:.0f} MB."
                        if g.get("synth_wall_s") else "."))
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--dir", required=True, help="bench-out folder")
    ap.add_argument("--report-only", action="store_true",
                    help="exit 0 whatever the verdicts (also BENCH_REPORT_ONLY=1)")
    a = ap.parse_args()
    r = collect(a.dir)
    r["verdicts"] = verdicts(r)
    with open(os.path.join(a.dir, "bench.json"), "w") as f:
        json.dump(r, f, indent=1)
    md = markdown(r)
    with open(os.path.join(a.dir, "bench.md"), "w") as f:
        f.write(md)
    print(md, end="")
    missed = [v for v in r["verdicts"] if v["ok"] is False]
    if missed:
        print(f"bench: {len(missed)} target(s) missed: " + "; ".join(v["name"] for v in missed), file=sys.stderr)
        if not (a.report_only or os.environ.get("BENCH_REPORT_ONLY") == "1"):
            sys.exit(1)


if __name__ == "__main__":
    main()

"""`make bench`'s verdicts on made-up inputs: bench/python/report.py and city_report.py exit 1
when a target is missed and 0 when all are met, and BENCH_REPORT_ONLY=1 (or --report-only)
only reports. The inputs are the files the benchmarks write, with chosen figures."""
import json
import os
import subprocess
import sys
import tempfile
import unittest

SOURCE = os.environ.get("NSG_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
REPORT = os.path.join(SOURCE, "bench", "python", "report.py")
CITY_REPORT = os.path.join(SOURCE, "bench", "python", "city_report.py")


def lidar_python(ratio):
    check = {"agree": True, "python_covered_cells": 100, "nsgraph_covered_cells": 100, "cells_only_python": 0,
             "cells_only_nsgraph": 0, "max_abs_dz_m": 0.0, "cells_z_bit_equal": 100, "python_z_checksum_m": 1.0,
             "nsgraph_z_checksum_m": 1.0}
    return {"ratio_nsgraph_over_python": ratio, "check": check, "same_sweeps": True, "sweeps": 782,
            "sweeps_per_s": 400.0, "nsgraph_sweeps_per_s": 400.0 * ratio, "numpy_version": "1.24.2"}


def generate_log(estimate_over_peak, peak_kib=100_000, covered_cells=2_000_000):
    estimate = int(estimate_over_peak * peak_kib * 1024)
    return (f"generate: 10 tiles written; 1000 sweeps, 0 images; 5.0 s (load 0.1, graph 0.1, lidar 0.2, plan 0.1, "
            f"camera 0.0, tiles 1.0)\ndebug: generate: estimated peak memory in bytes: {estimate}\n"
            f"debug: generate: LiDAR accumulated: 100 blocks, {covered_cells} covered cells\n"
            f"generate: 5.2 s wall, {peak_kib} KiB peak RSS\n")


class Verdicts(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = self.tmp.name

    def tearDown(self):
        self.tmp.cleanup()

    def write(self, name, content):
        with open(os.path.join(self.dir, name), "w") as f:
            f.write(content if isinstance(content, str) else json.dumps(content))

    def run_script(self, script, *extra, report_only=None):
        env = dict(os.environ)
        env.pop("BENCH_REPORT_ONLY", None)
        if report_only is not None:
            env["BENCH_REPORT_ONLY"] = report_only
        return subprocess.run([sys.executable, script, "--dir", self.dir, *extra], env=env, capture_output=True,
                              text=True)

    def verdicts(self):
        with open(os.path.join(self.dir, "bench.json")) as f:
            return {v["name"]: v for v in json.load(f)["verdicts"]}

    def write_city(self, estimate_1=1.0, estimate_2=1.0, lidarseg=None):
        self.write("generate-city-1.txt", generate_log(estimate_1))
        self.write("generate-city-2.txt", generate_log(estimate_2, peak_kib=103_000))
        if lidarseg is not None:
            self.write("generate-demo-lidarseg-2.txt", generate_log(lidarseg))

    def test_met_targets_exit_0(self):
        self.write("lidar_python.json", lidar_python(10.9))
        self.write("tables_python.json", {"ratio_nsgraph_over_python": 6.1})
        self.write_city()
        self.assertEqual(self.run_script(CITY_REPORT).returncode, 0)
        r = self.run_script(REPORT)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        v = self.verdicts()
        self.assertIs(v["LiDAR layer nsgraph / numpy, same sweeps, layers agree"]["ok"], True)
        self.assertEqual(v["LiDAR layer nsgraph / numpy, same sweeps, layers agree"]["kind"], "ratio")
        self.assertIs(v["city world memory estimate / peak, 2 thread(s)"]["ok"], True)
        self.assertIn("pass [ratio] JSON table load", r.stdout)

    def test_missed_ratio_exits_1_unless_report_only(self):
        self.write("lidar_python.json", lidar_python(9.5))
        r = self.run_script(REPORT)
        self.assertEqual(r.returncode, 1)
        self.assertIn("LiDAR layer nsgraph / numpy", r.stderr)
        self.assertIs(self.verdicts()["LiDAR layer nsgraph / numpy, same sweeps, layers agree"]["ok"], False)
        self.assertEqual(self.run_script(REPORT, report_only="1").returncode, 0)
        self.assertEqual(self.run_script(REPORT, "--report-only").returncode, 0)

    def test_layers_that_disagree_fail_even_at_a_good_ratio(self):
        doc = lidar_python(12.0)
        doc["check"]["agree"] = False
        self.write("lidar_python.json", doc)
        self.assertEqual(self.run_script(REPORT).returncode, 1)

    def test_absolute_rate_below_target_fails(self):
        self.write("dataset_read.json", {"tiles": 16, "tile_px": 256, "nsgraph_tiles_per_s": 250.0,
                                         "python_tiles_per_s": 200.0, "ratio_nsgraph_over_python": 1.25,
                                         "arrays_equal": True, "target_tiles_per_s": 300})
        r = self.run_script(REPORT)
        self.assertEqual(r.returncode, 1)
        self.assertEqual(self.verdicts()["nsgraph.Dataset tiles/s, 1 core, arrays equal"]["kind"], "absolute")

    def test_estimate_outside_the_band_fails_both_reports(self):
        self.write_city(estimate_2=1.27)  # the e2e world's figure before the estimate was mended
        r = self.run_script(CITY_REPORT)
        self.assertEqual(r.returncode, 1)
        self.assertIn("estimate", r.stderr)
        self.assertEqual(self.run_script(CITY_REPORT, report_only="1").returncode, 0)
        self.assertEqual(self.run_script(REPORT).returncode, 1)
        self.assertIs(self.verdicts()["city world memory estimate / peak, 2 thread(s)"]["ok"], False)

    def test_lidarseg_run_is_checked(self):
        self.write_city(lidarseg=0.70)
        self.assertEqual(self.run_script(CITY_REPORT).returncode, 1)
        self.write_city(lidarseg=1.09)
        self.assertEqual(self.run_script(CITY_REPORT).returncode, 0)
        r = self.run_script(REPORT)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("semantic_source: lidarseg", r.stdout)
        self.assertIs(self.verdicts()["demo_lidarseg world memory estimate / peak, 2 thread(s)"]["ok"], True)

    def test_nothing_run_is_not_a_pass_or_a_fail(self):
        r = self.run_script(REPORT)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertTrue(all(v["ok"] is None for v in self.verdicts().values()))


if __name__ == "__main__":
    unittest.main()

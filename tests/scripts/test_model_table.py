"""scripts/model_table.py (what `make baselines` and `make ablation` end with) on small
made-up score reports: the paired differences are the per-tile mean ± standard error worked
out by hand, and a row that drops beyond the tolerance (or is missing) fails the run."""
import json
import os
import subprocess
import sys
import tempfile
import unittest

SOURCE = os.environ.get("NSG_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
SCRIPT = os.path.join(SOURCE, "scripts", "model_table.py")


def score_report(per_tile):
    """A `nsgraph score` report holding only what the script reads: per-tile values and means."""
    metrics = sorted({m for t in per_tile.values() for m in t})
    mean = {m: sum(t[m] for t in per_tile.values()) / len(per_tile) for m in metrics}
    return {"tiles": per_tile, "aggregate": {"n_tiles": len(per_tile), "mean": mean}}


class ModelTable(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = self.tmp.name
        # Three tiles; graph − b1 APLS per tile: +0.1, 0.0, +0.2 → mean 0.1, sd 0.1, s.e. 0.1/√3.
        self.write_row("b1", {"t0": 0.3, "t1": 0.5, "t2": 0.2})
        self.write_row("b2", {"t0": 0.1, "t1": 0.2, "t2": 0.3})
        self.write_row("graph", {"t0": 0.4, "t1": 0.5, "t2": 0.4})

    def tearDown(self):
        self.tmp.cleanup()

    def write_row(self, name, apls):
        per_tile = {k: {"apls": v, "f1": 0.5, "topo_f1": v / 2} for k, v in apls.items()}
        with open(os.path.join(self.dir, f"{name}.score.json"), "w") as f:
            json.dump(score_report(per_tile), f)

    def expected(self, rows, tolerance=0.015):
        path = os.path.join(self.dir, "expected.json")
        with open(path, "w") as f:
            json.dump({"tolerance": tolerance, "rows": rows}, f)
        return path

    def run_table(self, expected):
        r = subprocess.run([sys.executable, SCRIPT, "--dir", self.dir, "--rows", "b1", "b2", "graph",
                            "--expected", expected], capture_output=True, text=True)
        with open(os.path.join(self.dir, "baselines.json")) as f:
            return r, json.load(f)

    def test_paired_differences_are_mean_and_standard_error(self):
        r, doc = self.run_table(self.expected({"graph": {"apls": 0.4333}}))
        self.assertEqual(r.returncode, 0, r.stderr)
        pairs = {(p["a"], p["b"], p["metric"]): p for p in doc["paired_differences"]}
        p = pairs[("graph", "b1", "apls")]
        self.assertEqual(p["n"], 3)
        self.assertAlmostEqual(p["mean"], 0.1, places=12)
        self.assertAlmostEqual(p["se"], 0.1 / 3 ** 0.5, places=12)
        # graph − b2: +0.3, +0.3, +0.1 → mean 0.2333, sd 0.11547, s.e. 0.066667.
        p = pairs[("graph", "b2", "apls")]
        self.assertAlmostEqual(p["mean"], 0.7 / 3, places=12)
        self.assertAlmostEqual(p["se"], 0.2 / 3, places=12)
        self.assertAlmostEqual(pairs[("graph", "b1", "f1")]["se"], 0.0, places=12)
        self.assertIn("| graph − b1, apls | +0.100 ± 0.058 | 3 |", r.stdout)
        self.assertIn("every row holds", r.stdout)

    def test_a_row_within_the_tolerance_passes_and_beyond_it_fails(self):
        r, _ = self.run_table(self.expected({"b1": {"apls": 0.34}}))  # measured 0.3333: 0.0067 below
        self.assertEqual(r.returncode, 0, r.stderr)
        r, doc = self.run_table(self.expected({"b1": {"apls": 0.36}}))  # 0.0267 below
        self.assertEqual(r.returncode, 1)
        self.assertIn("DROPPED: b1 apls 0.333", r.stdout)
        self.assertFalse(doc["checks"][0]["ok"])
        # A better score never fails.
        r, _ = self.run_table(self.expected({"b1": {"apls": 0.1}}))
        self.assertEqual(r.returncode, 0)

    def test_lower_is_better_metrics_fail_upwards(self):
        with open(os.path.join(self.dir, "b1.score.json")) as f:
            doc = json.load(f)
        doc["aggregate"]["mean"]["chamfer_mean_m"] = 1.2
        with open(os.path.join(self.dir, "b1.score.json"), "w") as f:
            json.dump(doc, f)
        r, _ = self.run_table(self.expected({"b1": {"chamfer_mean_m": 1.0}}))
        self.assertEqual(r.returncode, 1)
        r, _ = self.run_table(self.expected({"b1": {"chamfer_mean_m": 1.19}}))
        self.assertEqual(r.returncode, 0)

    def test_a_row_may_have_its_own_tolerance(self):
        # b1's APLS 0.3333 is 0.0267 below 0.36: beyond the file's 0.015, within a row's 0.03.
        r, doc = self.run_table(self.expected({"b1": {"apls": 0.36, "_tolerance": 0.03}}))
        self.assertEqual(r.returncode, 0, r.stdout)
        self.assertEqual([c["tolerance"] for c in doc["checks"]], [0.03])
        r, _ = self.run_table(self.expected({"b1": {"apls": 0.37, "_tolerance": 0.03}}))
        self.assertEqual(r.returncode, 1)

    def test_the_committed_values_cover_every_row_the_scripts_make(self):
        with open(os.path.join(SOURCE, "scripts", "model-expected.json")) as f:
            rows = json.load(f)["rows"]
        # Table II's rows carry the junction metrics (split detection, junction TOPO) too.
        table_ii = {"apls", "f1", "iou", "direction_accuracy", "topo_f1", "sda50_recall", "jtopo_f1"}
        self.assertEqual(rows["net"]["_tolerance"], 0.03)
        for name in ["b1", "b2", "graph", "net"]:
            self.assertEqual({k for k in rows[name] if not k.startswith("_")}, table_ii, name)
        for name in [f"ablation:{a}" for a in ["lidar", "lidar+rgb", "lidar+semantic", "lidar+vehicle", "all"]]:
            self.assertIn(name, rows)
            self.assertEqual(set(rows[name]), {"apls", "f1", "iou", "direction_accuracy", "topo_f1"}, name)


if __name__ == "__main__":
    unittest.main()

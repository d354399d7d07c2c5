"""nsgraph.score / score_tile / write_submission against the CLI on the same files."""
import json
import os
import sys
import tempfile
import unittest

import numpy as np

import fixtures
import nsgraph


def leaves(x, path=""):
    """Flattened (path, value) pairs of a JSON-like value."""
    if isinstance(x, dict):
        for k in sorted(x):
            yield from leaves(x[k], f"{path}/{k}")
    elif isinstance(x, list):
        for i, v in enumerate(x):
            yield from leaves(v, f"{path}/{i}")
    else:
        yield path, x


def perturbed_predictions(ds):
    """A deterministic imperfect prediction per tile: nodes moved, every third edge
    reversed, every fifth dropped, one tile left out (a missing prediction)."""
    rng = np.random.default_rng(5)
    out = {}
    for i, tile in enumerate(ds):
        if i == 1:
            continue
        nodes = tile["graph"]["nodes_px"] + rng.normal(0.0, 1.5, tile["graph"]["nodes_px"].shape)
        edges = tile["graph"]["edges"].copy()
        edges[::3] = edges[::3, ::-1]
        keep = np.arange(len(edges)) % 5 != 4
        out[tile["key"]] = (nodes, edges[keep])
    return out


class ScoreTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.root = fixtures.e2e_dataset("tar")
        cls.tmp = tempfile.TemporaryDirectory()
        cls.ds = nsgraph.Dataset(cls.root, "test", modalities=())
        cls.pred = perturbed_predictions(cls.ds)
        cls.submission = os.path.join(cls.tmp.name, "pred.json")
        nsgraph.write_submission(cls.submission, cls.pred)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def cli_report(self, *extra):
        out = os.path.join(self.tmp.name, "cli-report.json")
        fixtures.run_nsgraph("score", "--ground-truth", self.root, "--submission", self.submission, "--split", "test",
                             "--out", out, *extra)
        return fixtures.read_json(out)

    def assert_reports_equal(self, got, expected, skip=()):
        kept = lambda x: {p: v for p, v in leaves(x) if not any(p.startswith(s) for s in skip)}
        a, b = kept(got), kept(expected)
        self.assertEqual(sorted(a), sorted(b))
        compared = 0
        for path, value in b.items():
            if isinstance(value, float):
                self.assertAlmostEqual(a[path], value, delta=1e-12, msg=path)
                compared += 1
            else:
                self.assertEqual(a[path], value, msg=path)
        self.assertGreater(compared, 50)

    def test_metric_table_is_the_reports(self):
        # nsgraph.METRICS is the C++ table: its names are the report's metric keys, and only
        # the distances and the false-change rate are lower-is-better.
        py = nsgraph.score(self.root, self.submission, split="test")
        names = [m["name"] for m in nsgraph.METRICS]
        self.assertEqual(sorted(names), sorted(py["aggregate"]["mean"].keys()))
        self.assertEqual(len(set(names)), len(names))
        self.assertEqual({m["name"] for m in nsgraph.METRICS if m["lower_is_better"]},
                         {"chamfer_px2", "chamfer_m2", "chamfer_mean_m", "false_change_rate"})
        self.assertTrue(set(nsgraph.HEADLINE_METRICS) <= set(names))
        self.assertIn("apls", nsgraph.HEADLINE_METRICS)
        # The leaderboard's default columns: the summaries (no one-way halves, no summed
        # Chamfer, no directed TOPO variant), every headline among them, in the table's order.
        from nsgraph.hosting import LEADERBOARD_METRICS
        self.assertEqual(LEADERBOARD_METRICS, (
            "apls", "apls_directed", "apls_strict", "direction_accuracy", "f1", "iou", "chamfer_mean_m",
            "geo_precision", "geo_recall", "geo_f1", "topo_precision", "topo_recall", "topo_f1"))
        self.assertTrue(set(nsgraph.HEADLINE_METRICS) <= set(LEADERBOARD_METRICS))

    def test_python_scores_equal_the_cli(self):
        cli = self.cli_report()
        py = nsgraph.score(self.root, self.submission, split="test")
        self.assert_reports_equal(py, cli)
        self.assertEqual(py["aggregate"]["n_missing_predictions"], 1)

    def test_in_memory_submission_and_ground_truth_score_the_same(self):
        cli = self.cli_report()
        written = fixtures.read_json(self.submission)  # the rounded coordinates the CLI scored
        in_memory = nsgraph.score(self.root, written, split="test")
        # The receipt names the bytes scored: JSON text made from the dict, not the file.
        self.assert_reports_equal(in_memory, cli, skip=("/submission", "/receipt/submission"))
        self.assertEqual(in_memory["submission"], "<memory>")
        self.assertEqual(in_memory["receipt"]["results_sha256"], cli["receipt"]["results_sha256"])
        gt = {t["key"]: t["graph"] for t in self.ds}
        both = nsgraph.score(gt, written)
        # A ground truth in the submission format has no edge classes: the per-class recalls
        # (and their counts) are undefined, every other number the same.
        per_class = tuple(f"/{where}/{kind}_{c}" for where in ("aggregate/mean", "aggregate/n_defined",
                                                               "aggregate/n_undefined", "aggregate/sums")
                          for kind in ("geo_recall", "topo_recall", "geo_gt_samples", "geo_matched")
                          for c in ("lane", "connector", "in_intersection", "outside_intersection"))
        per_tile = tuple(f"/tiles/{key}/{kind}_{c}" for key in cli["tiles"]
                         for kind in ("geo_recall", "topo_recall", "counts/geo_gt_samples", "counts/geo_matched")
                         for c in ("lane", "connector", "in_intersection", "outside_intersection"))
        self.assert_reports_equal(both, cli, skip=("/submission", "/ground_truth", "/receipt") + per_class + per_tile)
        self.assertIsNone(both["aggregate"]["mean"]["geo_recall_connector"])
        self.assertIsNotNone(cli["aggregate"]["mean"]["geo_recall_connector"])
        self.assertEqual(both["receipt"]["ground_truth"]["kind"], "memory")
        # (so the results, and their hash, differ from the dataset's)
        self.assertNotEqual(both["receipt"]["results_sha256"], cli["receipt"]["results_sha256"])

    def test_parameters_reach_the_scorer(self):
        cli = self.cli_report()
        loose = nsgraph.score(self.root, self.submission, snap_m=6.0, lane_width_px=13)
        self.assertEqual(loose["params"]["snap_m"], 6.0)
        self.assertNotEqual(loose["aggregate"]["mean"]["f1"], cli["aggregate"]["mean"]["f1"])
        with self.assertRaises(nsgraph.ConfigError) as e:
            nsgraph.score(self.root, self.submission, snap_mm=6.0)
        self.assertIn("snap_mm", str(e.exception))

    def test_score_tile_equals_the_report_entry(self):
        report = nsgraph.score(self.root, self.submission)
        written = fixtures.read_json(self.submission)["tiles"]
        by_key = report["tiles"]
        for tile in list(self.ds)[:3]:
            key = tile["key"]
            got = nsgraph.score_tile(tile, written.get(key), key=key)
            self.assert_close(got, by_key[key])

    def assert_close(self, got, expected):
        a, b = dict(leaves(got)), dict(leaves(expected))
        self.assertEqual(sorted(a), sorted(b))
        for path, value in b.items():
            if isinstance(value, float):
                self.assertAlmostEqual(a[path], value, delta=1e-12, msg=path)
            else:
                self.assertEqual(a[path], value, msg=path)

    def test_perfect_prediction_scores_one(self):
        tile = self.ds[0]
        m = nsgraph.score_tile(tile, tile["graph"])
        self.assertAlmostEqual(m["apls"], 1.0)
        self.assertAlmostEqual(m["f1"], 1.0)
        self.assertEqual(m["counts"]["missing_prediction"], 0)
        self.assertEqual(nsgraph.score_tile(tile, None)["counts"]["missing_prediction"], 1)

    def test_score_tile_refuses_a_prediction_beyond_the_search_work_limit(self):
        # A connected junction (14 lanes each way, shared crossings) and a connected mesh
        # within every static limit: together beyond the search work limit, refused by name.
        sys.path.insert(0, os.path.join(fixtures.SOURCE_DIR, "bench", "adversarial"))
        from make_submission import gt_junction  # the bench's connected junction
        junction = gt_junction(14)
        side = 30
        mesh_nodes = [[i * 255 / (side - 1), j * 255 / (side - 1)] for j in range(side) for i in range(side)]
        mesh_edges = []
        for j in range(side - 1):
            for i in range(side - 1):
                k = j * side + i
                mesh_edges += [[k, k + 1], [k, k + side], [k, k + side + 1], [k + 1, k + side]]
        with self.assertRaises(nsgraph.SubmissionError) as e:
            nsgraph.score_tile(junction, {"nodes": mesh_nodes, "edges": mesh_edges}, key="busy")
        self.assertEqual(e.exception.issues[0]["check"], "submission.size")
        self.assertEqual(e.exception.issues[0]["subject"], "prediction:/tiles/busy")
        self.assertIn("units of work", str(e.exception))

    def test_a_written_submission_takes_about_46_bytes_per_node(self):
        # docs/scoring-limits.md states the size of a submission with exact coordinates.
        path = os.path.join(self.tmp.name, "exact.json")
        nsgraph.write_submission(path, {t["key"]: t["graph"] for t in self.ds})
        nodes = sum(len(t["graph"]["nodes_px"]) for t in self.ds)
        per_node = os.path.getsize(path) / nodes
        self.assertGreater(per_node, 36)
        self.assertLess(per_node, 56)

    def test_written_submission_is_valid_for_validate(self):
        r = fixtures.run_nsgraph("validate", "--submission", self.submission, "--dataset", self.root, "--split", "test",
                                 check=False)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)

    def test_a_leftover_shard_is_refused_and_the_listed_keys_agree(self):
        # A train shard copied in under a test shard name the manifest does not list: the
        # reader lists the manifest's keys only, the scorer refuses the folder by name.
        import shutil
        root = os.path.join(self.tmp.name, "leftover")
        shutil.copytree(self.root, root)
        shutil.copyfile(os.path.join(root, "shards", "train-000000.tar"), os.path.join(root, "shards", "test-000009.tar"))
        listed = sorted(nsgraph.Dataset(root, "test", modalities=()).keys)
        self.assertEqual(listed, sorted(self.ds.keys))
        with self.assertRaises(nsgraph.DataError) as e:
            nsgraph.score(root, self.submission, split="test")
        self.assertIn("test-000009.tar", str(e.exception))
        r = fixtures.run_nsgraph("score", "--quiet", "--ground-truth", root, "--submission", self.submission, check=False)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("test-000009.tar", r.stderr)


if __name__ == "__main__":
    unittest.main()

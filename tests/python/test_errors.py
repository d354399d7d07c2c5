"""Bad input raises a Python exception carrying the C++ message (file, record, expectation)."""
import json
import os
import shutil
import tempfile
import unittest

import numpy as np

import fixtures
import nsgraph


class ErrorsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.root = fixtures.e2e_dataset("tar")
        cls.tmp = tempfile.TemporaryDirectory()

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def path(self, name):
        return os.path.join(self.tmp.name, name)

    def test_a_folder_that_is_not_a_dataset(self):
        with self.assertRaises(nsgraph.IoError) as e:
            nsgraph.Dataset(self.tmp.name, "test")
        self.assertIn(os.path.join(self.tmp.name, "manifest.json"), str(e.exception))
        self.assertIsInstance(e.exception, OSError)
        self.assertEqual(e.exception.file, os.path.join(self.tmp.name, "manifest.json"))

    def test_a_split_that_does_not_exist(self):
        with self.assertRaises(nsgraph.ConfigError) as e:
            nsgraph.Dataset(self.root, "val")
        message = str(e.exception)
        self.assertIn("manifest.json", message)
        self.assertIn("split 'val'", message)
        self.assertIn("test, train", message)

    def test_unknown_modality(self):
        with self.assertRaises(nsgraph.ConfigError) as e:
            nsgraph.Dataset(self.root, "test", modalities=("lidar", "radar"))
        self.assertIn("radar", str(e.exception))

    def test_a_truncated_shard(self):
        copy = self.path("truncated")
        shutil.copytree(self.root, copy)
        manifest = fixtures.read_json(os.path.join(copy, "manifest.json"))
        shard = os.path.join(copy, next(s["file"] for s in manifest["shards"] if s["split"] == "test"))
        with open(shard, "r+b") as f:
            f.truncate(os.path.getsize(shard) // 2)  # inside a member
        with self.assertRaises(nsgraph.ParseError) as e:
            nsgraph.Dataset(copy, "test")
        self.assertIn(shard, str(e.exception))

    def test_a_malformed_submission(self):
        ds = nsgraph.Dataset(self.root, "test", modalities=())
        key = ds.key(0)
        bad = {"schema_version": "1", "tiles": {key: {"nodes": [[1.0, 2.0]], "edges": [[0, 7]]}}}
        with self.assertRaises(nsgraph.SubmissionError) as e:
            nsgraph.score(self.root, bad)
        self.assertIn("submission.indices", str(e.exception))
        self.assertIn(key, str(e.exception))
        self.assertEqual(e.exception.issues[0]["check"], "submission.indices")
        self.assertEqual(nsgraph.check_submission(bad)[0]["check"], "submission.indices")

    def test_a_submission_that_is_not_json(self):
        path = self.path("broken.json")
        with open(path, "w") as f:
            f.write('{"schema_version": "1", "tiles": {')
        with self.assertRaises(nsgraph.SubmissionError) as e:
            nsgraph.score(self.root, path)
        self.assertIn(path, str(e.exception))
        self.assertEqual(e.exception.issues[0]["check"], "submission.json")

    def test_a_missing_submission_file(self):
        with self.assertRaises(nsgraph.IoError) as e:
            nsgraph.score(self.root, self.path("absent.json"))
        self.assertIn("absent.json", str(e.exception))

    def test_write_submission_refuses_nan_and_bad_indices(self):
        path = self.path("nan.json")
        with self.assertRaises(nsgraph.SubmissionError):
            nsgraph.write_submission(path, {"k-test-000000": (np.array([[np.nan, 1.0]]), np.zeros((0, 2)))})
        self.assertFalse(os.path.exists(path))
        with self.assertRaises(nsgraph.SubmissionError) as e:
            nsgraph.write_submission(path, {"k-test-000000": ([[0.0, 1.0]], [[0, 3]])})
        self.assertIn("submission.indices", str(e.exception))

    def test_score_tile_with_an_edge_to_a_missing_node(self):
        # The index check of a file's tile: a SubmissionError naming the JSON path.
        with self.assertRaises(nsgraph.SubmissionError) as e:
            nsgraph.score_tile(([[0, 0], [1, 1]], [[0, 1]]), ([[0, 0]], [[0, 2]]), key="k")
        self.assertEqual([i["check"] for i in e.exception.issues], ["submission.indices"])
        self.assertIn("prediction:/tiles/k/edges/0/1", str(e.exception))
        self.assertIn("node index 2 out of range [0, 1)", str(e.exception))

    def test_float_edge_indices_are_refused_not_truncated(self):
        gt = ([[0.0, 0.0], [10.0, 0.0]], [[0, 1]])
        with self.assertRaises(nsgraph.DataError) as e:
            nsgraph.score_tile(gt, ([[0.0, 0.0], [10.0, 0.0]], [[0.7, 1.0]]))
        self.assertIn("integer node indices", str(e.exception))
        # Whole floats are indices all the same.
        self.assertAlmostEqual(nsgraph.score_tile(gt, ([[0.0, 0.0], [10.0, 0.0]], [[0.0, 1.0]]))["f1"], 1.0)

    def test_score_tile_refuses_what_a_file_could_not_hold(self):
        gt = ([[0.0, 0.0], [10.0, 0.0]], [[0, 1]])
        for bad in (float("nan"), float("inf"), -float("inf")):
            # An isolated node (no edge checks it) as well as one on an edge.
            for edges in (np.zeros((0, 2), np.int64), [[0, 1]]):
                with self.assertRaises(nsgraph.SubmissionError) as e:
                    nsgraph.score_tile(gt, ([[1.0, 2.0], [bad, 3.0]], edges), key="k")
                checks = {i["check"] for i in e.exception.issues}
                self.assertIn("submission.finite", checks, str(e.exception))
                self.assertIn("prediction:/tiles/k/nodes/1/0", str(e.exception))
        with self.assertRaises(nsgraph.DataError) as e:
            nsgraph.score_tile(([[0.0, float("nan")]], np.zeros((0, 2), np.int64)), gt, key="k")
        self.assertIn("ground truth:/tiles/k/nodes/0/1", str(e.exception))
        self.assertIn("a finite coordinate", str(e.exception))


if __name__ == "__main__":
    unittest.main()


class ModelCommandHelpTest(unittest.TestCase):
    """`python -m nsgraph.models.<command> --help` shows each option's default, as the C++
    commands' --help does (it showed none)."""

    def test_every_option_with_a_default_shows_it(self):
        import subprocess
        import sys
        expected = {"train": ["passes over the split (default: 60)", "(default: 0.003)", "(default: 0)"],
                    "predict": ["the split to predict (default: test)"],
                    "calibrate": ["(default: train)", "(default: 4)"],
                    "export": ["(default: 0)"]}
        for module, parts in expected.items():
            r = subprocess.run([sys.executable, "-m", "nsgraph.models." + module, "--help"], capture_output=True,
                               text=True, timeout=60)
            self.assertEqual(r.returncode, 0, r.stderr)
            text = " ".join(r.stdout.split())  # argparse wraps lines
            for part in parts:
                self.assertIn(part, text, module)
            self.assertNotIn("(default: None)", text, module)
            self.assertNotIn("(default: False)", text, module)

"""examples/train_lanedir.py trains a few steps on a handful of e2e tiles and scores."""
import json
import os
import subprocess
import sys
import tempfile
import unittest

import fixtures


class ExampleTest(unittest.TestCase):
    def test_train_lanedir_runs_and_scores(self):
        root = fixtures.e2e_dataset("tar")
        script = os.path.join(fixtures.SOURCE_DIR, "examples", "train_lanedir.py")
        with tempfile.TemporaryDirectory() as out:
            r = subprocess.run([sys.executable, script, "--dataset", root, "--steps", "3", "--max-tiles", "4",
                                "--workers", "2", "--out", out], capture_output=True, text=True, timeout=120)
            self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
            self.assertIn("step 3: loss", r.stdout)
            self.assertIn("scored", r.stdout)
            report = fixtures.read_json(os.path.join(out, "report.json"))
            self.assertGreater(report["aggregate"]["n_tiles"], 0)
            self.assertEqual(len(fixtures.read_json(os.path.join(out, "submission.json"))["tiles"]), 4)


if __name__ == "__main__":
    unittest.main()

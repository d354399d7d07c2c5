"""Hostile input through the Python package: clear nsgraph errors naming the file, no crash
(a segfault would end this process), no allocation from a lying header; the hosting entry
point nsgraph.evaluate."""
import io
import json
import os
import resource
import shutil
import struct
import tarfile
import tempfile
import unittest

import numpy as np

import fixtures
import nsgraph


def lying_tiff(width, height, bands=1):
    """A little-endian uncompressed one-strip TIFF whose header claims width x height x
    bands uint8 pixels but carries 1 KiB of data."""
    entries = [(256, 4, width), (257, 4, height), (258, 3, 8), (259, 3, 1), (262, 3, 1), (273, 4, None),
               (277, 3, bands), (278, 4, height), (279, 4, (width * height * bands) % 2**32)]
    data_at = 8 + 2 + 12 * len(entries) + 4
    out = b"II*\x00" + struct.pack("<I", 8) + struct.pack("<H", len(entries))
    for tag, typ, value in entries:
        value = data_at if value is None else value
        out += struct.pack("<HHI", tag, typ, 1) + (struct.pack("<HH", value, 0) if typ == 3 else struct.pack("<I", value))
    return out + struct.pack("<I", 0) + bytes(1024)


class HostileDatasetTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.source = fixtures.e2e_dataset("tar")
        cls.tmp = tempfile.TemporaryDirectory()

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def copy_with(self, name, replace):
        """A copy of the e2e dataset whose first test tile has the members in `replace`
        (suffix -> bytes) instead of its own."""
        root = os.path.join(self.tmp.name, name)
        shutil.copytree(self.source, root)
        manifest = fixtures.read_json(os.path.join(root, "manifest.json"))
        shard = os.path.join(root, next(s["file"] for s in manifest["shards"] if s["split"] == "test"))
        with tarfile.open(shard) as t:
            members = [(m.name, t.extractfile(m).read()) for m in t.getmembers() if m.isfile()]
        first = members[0][0].split(".")[0]
        with tarfile.open(shard, "w", format=tarfile.PAX_FORMAT) as t:
            for member, data in members:
                key, suffix = member.split(".", 1)
                if key == first and suffix in replace:
                    data = replace[suffix]
                info = tarfile.TarInfo(member)
                info.size = len(data)
                t.addfile(info, io.BytesIO(data))
        return root, first

    def test_deeply_nested_meta_json(self):
        root, key = self.copy_with("deep", {"meta.json": b"[" * 30000 + b"]" * 30000})
        ds = nsgraph.Dataset(root, "test", modalities=())
        with self.assertRaises(nsgraph.ParseError) as e:
            ds[0]
        self.assertIn(f"{key}.meta.json", str(e.exception))
        self.assertIn("nested at most 64 deep", str(e.exception))

    def test_duplicate_key_in_meta_json(self):
        root, key = self.copy_with("dupkey", {"meta.json": b'{"key": "a", "key": "b"}'})
        with self.assertRaises(nsgraph.ParseError) as e:
            nsgraph.Dataset(root, "test", modalities=())[0]
        self.assertIn("each key once", str(e.exception))

    def test_tiff_header_claiming_a_huge_image(self):
        root, key = self.copy_with("huge", {"lidar.tif": lying_tiff(32768, 32768)})
        ds = nsgraph.Dataset(root, "test", modalities=("lidar",))
        before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        with self.assertRaises(nsgraph.DataError) as e:
            ds[0]
        grown_mb = (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before) / 1024
        self.assertLess(grown_mb, 100)
        self.assertIn(f"{key}.lidar.tif", str(e.exception))
        self.assertIn("got 32768 x 32768", str(e.exception))

    def test_layers_of_the_wrong_shape_or_type(self):
        tile = nsgraph.Dataset(self.source, "test", modalities=())
        lidar = tile.member_bytes(0, "lidar.tif")
        root, key = self.copy_with("shape", {"rgb.tif": lidar, "vehicle.tif": lidar})
        ds = nsgraph.Dataset(root, "test", modalities=("rgb",))
        with self.assertRaises(nsgraph.DataError) as e:
            ds[0]
        self.assertIn(f"{key}.rgb.tif", str(e.exception))
        self.assertIn("uint8 x 3", str(e.exception))
        with self.assertRaises(nsgraph.DataError) as e:
            nsgraph.Dataset(root, "test", modalities=("vehicle",))[0]
        self.assertIn("float32 x 1", str(e.exception))


class HostileSubmissionTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.root = fixtures.e2e_dataset("tar")
        cls.tmp = tempfile.TemporaryDirectory()

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_non_utf8_bytes_name_the_file(self):
        path = os.path.join(self.tmp.name, "latin1.json")
        with open(path, "wb") as f:
            f.write(b'{"schema_version":"1","tiles":{"caf\xe9":{"nodes":[],"edges":[]}}}')
        with self.assertRaises(nsgraph.SubmissionError) as e:
            nsgraph.score(self.root, path)
        self.assertIn(path, str(e.exception))
        self.assertEqual(e.exception.issues[0]["check"], "submission.json")

    def test_nan_in_memory_is_an_issue(self):
        issues = nsgraph.check_submission({"k": ([[float("nan"), 1.0]], np.zeros((0, 2), np.int64))})
        self.assertEqual([i["check"] for i in issues], ["submission.json"])
        self.assertIn("NaN", issues[0]["message"])

    def test_max_seconds_stops_score_and_evaluate(self):
        path = os.path.join(self.tmp.name, "budget.json")
        ds = nsgraph.Dataset(self.root, "test", modalities=())
        nsgraph.write_submission(path, {t["key"]: t for t in ds})
        with self.assertRaises(nsgraph.ConfigError) as e:
            nsgraph.score(self.root, path, max_seconds=1e-9)
        self.assertIn("--max-seconds", str(e.exception))
        with self.assertRaises(nsgraph.ConfigError):
            nsgraph.evaluate(self.root, path, "test-phase", max_seconds=1e-9)

    def test_far_nodes_are_refused_not_scored_infinite(self):
        # Two isolated nodes at ±1e160 once gave Chamfer = inf (JSON Infinity from evaluate).
        gt = ([[0.0, 0.0], [10.0, 0.0]], [[0, 1]])
        far = ([[1e160, 0.0], [-1e160, 0.0]], np.zeros((0, 2), np.int64))
        with self.assertRaises(nsgraph.SubmissionError) as e:
            nsgraph.score_tile(gt, far)
        self.assertEqual({i["check"] for i in e.exception.issues}, {"submission.size"})
        issues = nsgraph.check_submission({"k": far})
        self.assertIn("within ±100000 px", issues[0]["message"])

    def test_score_tile_has_the_limits(self):
        gt = ([[0.0, 0.0], [10.0, 0.0]], [[0, 1]])
        nodes = np.random.default_rng(1).uniform(0, 256, (5001, 2))
        with self.assertRaises(nsgraph.SubmissionError) as e:
            nsgraph.score_tile(gt, (nodes, np.zeros((0, 2), np.int64)))
        self.assertEqual([i["check"] for i in e.exception.issues], ["submission.size"])
        self.assertIn("5001 nodes; at most 5000", str(e.exception))

    def test_evaluate_in_the_hosted_challenge_form(self):
        ds = nsgraph.Dataset(self.root, "test", modalities=())
        path = os.path.join(self.tmp.name, "sub.json")
        nsgraph.write_submission(path, {t["key"]: t for t in ds})
        out = nsgraph.evaluate(self.root, path, "test-phase", split="test", submission_metadata={})
        self.assertEqual(list(out), ["result", "submission_result"])
        self.assertEqual(list(out["result"][0]), ["test"])
        values = out["result"][0]["test"]
        self.assertEqual(values, out["submission_result"])
        self.assertAlmostEqual(values["apls"], 1.0, places=3)  # the ground truth itself (rounded to 1/1000 px)
        self.assertAlmostEqual(values["f1"], 1.0, places=3)
        self.assertEqual(values["n_tiles"], len(ds))
        report = nsgraph.score(self.root, path)
        self.assertEqual(values["topo_f1"], report["aggregate"]["mean"]["topo_f1"])


if __name__ == "__main__":
    unittest.main()

"""nsgraph.Dataset against independent readers of the same files: tarfile + PIL for the
GeoTIFFs, json for graph and meta, the folder layout against the tar layout."""
import io
import json
import os
import tarfile
import tempfile
import threading
import unittest

import numpy as np
from PIL import Image

import fixtures
import nsgraph

LAYERS = ("lidar", "rgb", "semantic", "vehicle", "coverage")


def tar_tiles(root, split):
    """{key: {suffix: bytes}} of every shard of the split, in manifest order (keys list)."""
    manifest = fixtures.read_json(os.path.join(root, "manifest.json"))
    keys, files = [], {}
    for shard in manifest["shards"]:
        if shard["split"] != split:
            continue
        with tarfile.open(os.path.join(root, shard["file"])) as tar:
            for m in tar.getmembers():
                key, suffix = m.name.split(".", 1)
                if key not in files:
                    keys.append(key)
                    files[key] = {}
                files[key][suffix] = tar.extractfile(m).read()
    return keys, files


def pil_array(data):
    return np.array(Image.open(io.BytesIO(data)))


class DatasetTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.root = fixtures.e2e_dataset("tar")
        cls.folder_root = fixtures.e2e_dataset("folder")

    def test_every_array_equals_the_geotiff_and_json(self):
        for split in ("train", "test"):
            ds = nsgraph.Dataset(self.root, split)
            keys, files = tar_tiles(self.root, split)
            self.assertGreater(len(ds), 0)
            self.assertEqual(ds.keys, keys)
            for i, tile in enumerate(ds):
                self.assertEqual(tile["key"], keys[i])
                member = files[keys[i]]
                for layer in LAYERS:
                    expected = pil_array(member[layer + ".tif"])
                    got = tile[layer]
                    self.assertEqual(got.dtype, expected.dtype, layer)
                    self.assertEqual(got.shape, expected.shape, layer)
                    np.testing.assert_array_equal(got, expected, err_msg=f"{keys[i]} {layer}")
                self.assertEqual(tile["lidar"].dtype, np.uint8)
                self.assertEqual(tile["rgb"].shape[2], 3)
                self.assertEqual(tile["vehicle"].dtype, np.float32)
                graph = json.loads(member["graph.json"])
                ids = {n["id"]: k for k, n in enumerate(graph["nodes"])}
                np.testing.assert_array_equal(tile["graph"]["nodes_px"],
                                              np.array([[n["u"], n["v"]] for n in graph["nodes"]]).reshape(-1, 2))
                np.testing.assert_array_equal(tile["graph"]["nodes_m"],
                                              np.array([[n["x"], n["y"]] for n in graph["nodes"]]).reshape(-1, 2))
                np.testing.assert_array_equal(tile["graph"]["edges"].reshape(-1, 2),
                                              np.array([[ids[e["source"]], ids[e["target"]]] for e in graph["edges"]],
                                                       dtype=np.int64).reshape(-1, 2))
                self.assertEqual(tile["graph"]["edges"].dtype, np.int64)
                self.assertEqual(tile["graph"]["lane_tokens"], [e["lane_token"] for e in graph["edges"]])
                self.check_attributes(tile["graph"], graph, ids)
                self.assertEqual(tile["meta"], json.loads(member["meta.json"]))
        self.assertGreater(self.seen_lane_changes, 0, "the world has streets of two lanes a direction")

    def check_attributes(self, got, graph, ids):
        """The graph attributes as graph.json states them, by their codes."""
        self.assertEqual([nsgraph.JUNCTIONS[c] for c in got["junction"]], [n["junction"] for n in graph["nodes"]])
        self.assertEqual([nsgraph.TURNS[c] for c in got["turn"]], [e["turn"] for e in graph["edges"]])
        self.assertEqual(got["connector"].dtype, np.bool_)
        self.assertEqual(got["connector"].tolist(), [e["kind"] == "connector" for e in graph["edges"]])
        self.assertEqual(got["in_intersection"].tolist(), [e["in_intersection"] for e in graph["edges"]])
        np.testing.assert_array_equal(got["lane_changes"].reshape(-1, 2),
                                      np.array([[ids[c["source"]], ids[c["target"]]] for c in graph["lane_changes"]],
                                               dtype=np.int64).reshape(-1, 2))
        self.assertEqual(got["lane_change_tokens"],
                         [(c["from_lane_token"], c["to_lane_token"]) for c in graph["lane_changes"]])
        self.seen_lane_changes = getattr(self, "seen_lane_changes", 0) + len(graph["lane_changes"])

    def test_the_layer_declaration_comes_from_the_library_and_matches_the_files(self):
        # nsgraph.LAYERS is io::tile_members() of the C++ library: names in member order,
        # dtype and bands of the decoded arrays, the GeoTIFFs' no-data tags, coverage bits.
        self.assertEqual(tuple(nsgraph.LAYERS), LAYERS)
        self.assertEqual([m["file"] for m in nsgraph.TILE_MEMBERS],
                         [layer + ".tif" for layer in LAYERS] + ["graph.json", "meta.json"])
        self.assertEqual(nsgraph.MODALITIES, ("lidar", "rgb", "semantic", "vehicle"))
        keys, files = tar_tiles(self.root, "test")
        tile = nsgraph.Dataset(self.root, "test")[0]
        for name, layer in nsgraph.LAYERS.items():
            self.assertEqual(tile[name].dtype, np.dtype(layer["dtype"]), name)
            self.assertEqual(tile[name].shape[2] if tile[name].ndim == 3 else 1, layer["bands"], name)
            tag = Image.open(io.BytesIO(files[keys[0]][layer["file"]])).tag_v2.get(42113)  # GDAL_NODATA
            self.assertEqual(None if tag is None else float(tag.strip("\x00")), layer["nodata"], name)
            if layer["coverage_bit"]:
                nodata = np.all(tile[name] == layer["nodata"], axis=-1) if layer["bands"] > 1 else tile[name] == layer["nodata"]
                np.testing.assert_array_equal((tile["coverage"] & layer["coverage_bit"]) != 0, ~nodata, err_msg=name)

    def test_the_graph_nodes_lie_on_their_pixels(self):
        # u = (x − x_west) / 0.2 − 0.5: the two coordinate sets agree through meta's bounds
        tile = nsgraph.Dataset(self.root, "test")[0]
        x_west, _, _, y_north = tile["meta"]["bounds_m"]
        uv, xy = tile["graph"]["nodes_px"], tile["graph"]["nodes_m"]
        np.testing.assert_allclose(uv[:, 0], (xy[:, 0] - x_west) / 0.2 - 0.5, atol=1e-6)
        np.testing.assert_allclose(uv[:, 1], (y_north - xy[:, 1]) / 0.2 - 0.5, atol=1e-6)

    def test_folder_layout_reads_the_same_tiles(self):
        tar_ds = nsgraph.Dataset(self.root, "test")
        folder_ds = nsgraph.Dataset(self.folder_root, "test")
        self.assertEqual(tar_ds.keys, folder_ds.keys)
        for a, b in zip(tar_ds, folder_ds):
            for layer in LAYERS:
                np.testing.assert_array_equal(a[layer], b[layer])
            np.testing.assert_array_equal(a["graph"]["nodes_px"], b["graph"]["nodes_px"])
            self.assertEqual(a["meta"], b["meta"])

    def test_modalities_random_access_and_negative_indices(self):
        ds = nsgraph.Dataset(self.root, "train", modalities=("lidar",), meta=False)
        n = len(ds)
        last = ds[-1]
        self.assertEqual(last["key"], ds.key(n - 1))
        self.assertEqual(set(k for k in last if k in LAYERS), {"lidar", "coverage"})
        self.assertNotIn("meta", last)
        order = [n - 1, 0, n // 2, 1, n - 1]
        full = nsgraph.Dataset(self.root, "train")
        for i in order:
            np.testing.assert_array_equal(ds[i]["lidar"], full[i]["lidar"])
        with self.assertRaises(IndexError):
            ds[n]

    def test_tiles_by_key_and_modalities_as_text(self):
        ds = nsgraph.Dataset(self.root, "train", modalities="lidar", meta=False)
        self.assertEqual(ds.modalities, ("lidar",))  # not five letters
        self.assertEqual(nsgraph.Dataset(self.root, "train", modalities="lidar, rgb").modalities, ("lidar", "rgb"))
        self.assertEqual(nsgraph.Dataset(self.root, "train", modalities="all").modalities, nsgraph.MODALITIES)
        key = ds.keys[2]
        self.assertEqual(ds.index(key), 2)
        self.assertIn(key, ds)
        self.assertNotIn("nope", ds)
        np.testing.assert_array_equal(ds[key]["lidar"], ds[2]["lidar"])
        self.assertEqual(ds.get(key)["key"], key)
        self.assertIsNone(ds.get("nope"))
        with self.assertRaises(ValueError) as e:
            ds.index("nope")
        self.assertIn("split 'train'", str(e.exception))
        with self.assertRaises(nsgraph.ConfigError):
            nsgraph.Dataset(self.root, "train", modalities="lidar,rbg")

    def test_threads_read_in_parallel_without_interference(self):
        ds = nsgraph.Dataset(self.root, "train")
        expected = [t["lidar"].copy() for t in ds]
        errors = []

        def work(offset):
            for k in range(len(ds)):
                i = (k + offset) % len(ds)
                if not np.array_equal(ds[i]["lidar"], expected[i]):
                    errors.append(i)

        threads = [threading.Thread(target=work, args=(o,)) for o in range(4)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        self.assertEqual(errors, [])

    def test_pickles_by_arguments(self):
        import pickle
        ds = nsgraph.Dataset(self.root, "test", modalities=("rgb",))
        again = pickle.loads(pickle.dumps(ds))
        self.assertEqual(again.keys, ds.keys)
        np.testing.assert_array_equal(again[0]["rgb"], ds[0]["rgb"])




class LadderTest(unittest.TestCase):
    """Dataset(rung=k) against the rung shards read with tarfile and json."""

    def test_rung_tiles_are_the_split_tiles_keys_with_their_rung(self):
        root = fixtures.ladder_dataset()
        self.assertEqual(nsgraph.Dataset.rungs(root), [1, 2, 4])
        self.assertEqual(nsgraph.Dataset.rungs(fixtures.e2e_dataset()), [])
        split = nsgraph.Dataset(root, "test", modalities="lidar")
        for rung in (1, 2, 4):
            ds = nsgraph.Dataset(root, "test", modalities="lidar", rung=rung)
            self.assertEqual(ds.keys, [k + f"-r{rung}" for k in split.keys])
            manifest = fixtures.read_json(os.path.join(root, "manifest.json"))
            files = {}
            for shard in manifest["ladder"]["shards"]:
                if shard["rung"] != rung:
                    continue
                with tarfile.open(os.path.join(root, shard["file"])) as tar:
                    for m in tar.getmembers():
                        key, suffix = m.name.split(".", 1)
                        files.setdefault(key, {})[suffix] = tar.extractfile(m).read()
            for i in range(len(ds)):
                tile = ds[i]
                meta = json.loads(files[tile["key"]]["meta.json"])
                self.assertEqual(tile["meta"], meta)
                self.assertEqual(tile["meta"]["ladder"]["rung"], rung)
                self.assertLessEqual(len(tile["meta"]["scenes"]), rung)
                np.testing.assert_array_equal(tile["lidar"], pil_array(files[tile["key"]]["lidar.tif"]))
        self.assertEqual(nsgraph.Dataset(root, "test", rung="all").keys, split.keys)

    def test_a_rung_the_dataset_lacks_is_named(self):
        root = fixtures.ladder_dataset()
        with self.assertRaisesRegex(nsgraph.ConfigError, "test-r1, test-r2, test-r4"):
            nsgraph.Dataset(root, "test", rung=3)
        # The rung's split name reads the same tiles.
        self.assertEqual(nsgraph.Dataset(root, "test-r2").keys, nsgraph.Dataset(root, "test", rung=2).keys)
        with self.assertRaises(nsgraph.ConfigError):
            nsgraph.Dataset(root, "test", rung=0)


class MapUpdateTest(unittest.TestCase):
    """A map-update dataset (generate's splits.preset map-update) read by nsgraph.Dataset: each
    tile's prior graph beside its graph, every edge's change code into MAP_CHANGES, equal to
    the labels graph.json holds."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory(prefix="nsg-map-update-")
        release = os.path.join(cls.tmp.name, "release")
        fixtures.run_nsgraph("synth", "--quiet", "--config", os.path.join(fixtures.SOURCE_DIR, "samples/synth/tiny.json"),
                             "--out", release, "--set", "scenes.count=6", "--set", "scenes.capture_days=2", "--set", "changes.from_day=1",
                             "--set", "changes.lanes_closed=1", "--set", "changes.turns_removed=1")
        date = fixtures.read_json(os.path.join(release, "changes.json"))["date"]
        cls.root = os.path.join(cls.tmp.name, "dataset")
        fixtures.run_nsgraph("generate", "--quiet", "--config", fixtures.GENERATE_CONFIG, "--dataroot", release,
                             "--version", "v1.0-mini", "--out", cls.root, "--layout", "folder",
                             "--set", "splits.preset=map-update", "--set", f"splits.before_after_date={date}")

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_prior_graph_and_change_codes_are_graph_jsons(self):
        self.assertEqual(nsgraph.MAP_CHANGES, ("", "unchanged", "added", "removed", "moved", "retyped"))
        counts = fixtures.read_json(os.path.join(self.root, "manifest.json"))["locations"][0]["counts"]
        seen = set()
        tiles = [(split, t) for split in ("train", "test") if counts[split] for t in nsgraph.Dataset(self.root, split)]
        self.assertGreater(len(tiles), 0)
        for split, t in tiles:
            doc = fixtures.read_json(os.path.join(self.root, "tiles", split, t["key"], t["key"] + ".graph.json"))
            for name, graph in (("graph", doc), ("prior_graph", doc["prior"])):
                labels = [nsgraph.MAP_CHANGES[c] for c in t[name]["change"]]
                self.assertEqual(labels, [e["change"] for e in graph["edges"]], t["key"])
                self.assertEqual(len(t[name]["edges"]), len(graph["edges"]))
                seen.update((name, label) for label in labels)
        self.assertNotIn(("graph", "removed"), seen)
        self.assertIn(("graph", "unchanged"), seen)
        self.assertIn(("prior_graph", "removed"), seen)

    def test_score_tile_takes_the_prior_graph_and_agrees_with_the_cli(self):
        # Per tile, nsgraph.score_tile on ds[i] scores the change metrics against its prior
        # graph exactly as `nsgraph score` on the dataset does; copying the prior detects nothing.
        counts = fixtures.read_json(os.path.join(self.root, "manifest.json"))["locations"][0]["counts"]
        split = "test" if counts["test"] else "train"
        tiles = list(nsgraph.Dataset(self.root, split))
        submission = os.path.join(self.tmp.name, f"{split}-prior.json")
        report = os.path.join(self.tmp.name, f"{split}-report.json")
        fixtures.run_nsgraph("predict", "--quiet", "--model", "prior", "--dataset", self.root, "--split", split,
                             "--out", submission)
        fixtures.run_nsgraph("score", "--quiet", "--ground-truth", self.root, "--split", split, "--submission",
                             submission, "--out", report)
        cli = fixtures.read_json(report)["tiles"]
        removed = 0
        for t in tiles:
            ours = nsgraph.score_tile(t, t["prior_graph"], key=t["key"])
            for name in ("change_recall", "change_precision", "false_change_rate", "unchanged_precision",
                         "geo_recall_changed", "geo_recall_unchanged"):
                self.assertEqual(ours[name], cli[t["key"]][name], f"{t['key']} {name}")
            self.assertIn(ours["change_recall"], (None, 0.0))
            self.assertIsNone(ours["change_precision"])
            removed += ours["counts"]["change_samples_removed"]
            # without the prior the change metrics are undefined, never 0
            self.assertIsNone(nsgraph.score_tile(t["graph"], t["prior_graph"], key=t["key"])["false_change_rate"])
        self.assertGreater(removed, 0)

    def test_other_datasets_have_no_prior_graph(self):
        t = nsgraph.Dataset(fixtures.e2e_dataset("tar"), "test")[0]
        self.assertNotIn("prior_graph", t)
        self.assertTrue((t["graph"]["change"] == 0).all())


class SemanticClassesTest(unittest.TestCase):
    def test_the_one_table_is_the_samples_file_and_the_networks_channels(self):
        # nsg/core/semantic_classes.h, exported by the extension: the same as the samples
        # file users read, and the network's one-hot channel count.
        path = os.path.join(os.environ["NSG_SOURCE_DIR"], "samples", "semantic-classes.json")
        with open(path) as f:
            doc = json.load(f)
        self.assertEqual(nsgraph.SEMANTIC_VOID, doc["void_id"])
        self.assertEqual([(c["id"], c["name"], tuple(c["color"])) for c in nsgraph.SEMANTIC_CLASSES],
                         [(c["id"], c["name"], tuple(c["color"])) for c in doc["classes"]])
        from nsgraph.models.lanegraphnet import DIRECTION_CLASSES, INPUTS
        self.assertEqual(INPUTS["semantic"], len(doc["classes"]))
        self.assertEqual(DIRECTION_CLASSES, 19)


if __name__ == "__main__":
    unittest.main()

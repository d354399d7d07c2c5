"""nsgraph.frames: the records of an export (through its manifest), images decoded on
demand, the PyTorch collate, score_frames (= nsgraph score --frames) and evaluate's frames
phase, on the e2e dataset's frames."""
import hashlib
import json
import os
import resource
import shutil
import tempfile
import time
import unittest

import numpy as np

import fixtures
import nsgraph
import nsgraph.frames
import nsgraph.hosting

import nsgraph.torch  # python3-torch is a test dependency (cmake/debian-packages.txt)


def export(tmp):
    out = os.path.join(tmp, "frames")
    fixtures.run_nsgraph("frames", "--quiet", "--dataset", fixtures.e2e_dataset("tar"), "--out", out,
                         "--overlap", "keep")
    return out


def copy_results(ds):
    """The split's ground truth as an OpenLane-V2 results document (distinct confidences)."""
    results, conf = {}, 0.999
    for i in range(len(ds)):
        item = ds[i]
        lanes = []
        for k, c in enumerate(item["centerlines"]):
            lanes.append({"id": k, "points": c.astype(float).tolist(), "confidence": conf})
            conf -= 1e-4
        results[item["token"]] = {"predictions": {"lane_centerline": lanes,
                                                  "topology_lclc": item["topology"].astype(float).tolist()}}
    return {"results": results}


class FramesTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="nsg-py-frames-")
        cls.root = export(cls.tmp)
        cls.manifest = fixtures.read_json(os.path.join(cls.root, "manifest.json"))

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_items_carry_the_records_calibration_and_lanes(self):
        ds = nsgraph.frames.Dataset(self.root, "test")
        self.assertEqual(len(ds), self.manifest["counts"]["frames"]["test"])
        item = ds[0]
        record = ds.record(0)
        self.assertEqual(item["token"], record["sample_token"])
        cam = next(iter(record["sensor"]))
        np.testing.assert_array_equal(item["cameras"][cam]["K"], np.asarray(record["sensor"][cam]["intrinsic"]["K"]))
        ext = item["cameras"][cam]["extrinsic"]
        np.testing.assert_array_equal(ext[:3, 3], record["sensor"][cam]["extrinsic"]["translation"])
        np.testing.assert_array_equal(ext[3], [0, 0, 0, 1])
        self.assertTrue(os.path.isfile(item["cameras"][cam]["image_path"]))
        n = len(record["annotation"]["lane_centerline"])
        self.assertEqual(len(item["centerlines"]), n)
        self.assertEqual(item["centerlines"][0].shape, (11, 3))
        self.assertEqual(item["topology"].shape, (n, n))
        self.assertEqual(int(item["topology"].sum()), sum(map(sum, record["annotation"]["topology_lclc"])))
        # The pose puts the ego-frame centerlines back on the map plane (z = 0).
        p = np.c_[item["centerlines_2m"][0], np.ones(len(item["centerlines_2m"][0]))] @ item["pose"].T
        np.testing.assert_allclose(p[:, 2], 0.0, atol=1e-3)
        # Version 2: a lane segment per centerline, lines as (10, 3) arrays, the same topology.
        ann = record["annotation"]
        self.assertEqual(record["version"], "nsgraph-frames-2")
        self.assertEqual([s["id"] for s in ann["lane_segment"]], [c["id"] for c in ann["lane_centerline"]])
        self.assertEqual(ann["lane_segment"][0]["left_laneline"].shape, (10, 3))
        self.assertIn(ann["lane_segment"][0]["right_laneline_type"], (0, 1, 2))
        np.testing.assert_array_equal(ann["topology_lsls"], ann["topology_lclc"])
        self.assertTrue(all(a["category"] in (1, 2) and a["points"].shape[1] == 3 for a in ann["area"]))

    def test_images_decode_on_demand_at_the_records_size(self):
        ds = nsgraph.frames.Dataset(self.root, "train", images=True)
        item = ds[0]
        for ch, cam in item["cameras"].items():
            self.assertEqual(item["images"][ch].shape, (cam["height"], cam["width"], 3))
            self.assertEqual(item["images"][ch].dtype, np.uint8)
        half = nsgraph.frames.Dataset(self.root, "train", image_scale=2)
        cam = next(iter(half[0]["cameras"].values()))
        self.assertEqual(half.image(cam).shape, ((cam["height"] + 1) // 2, (cam["width"] + 1) // 2, 3))

    def test_a_tampered_record_is_refused_by_name(self):
        tmp = tempfile.mkdtemp(prefix="nsg-py-frames-bad-")
        try:
            copy = os.path.join(tmp, "frames")
            shutil.copytree(self.root, copy)
            ds = nsgraph.frames.Dataset(copy, "test")
            path = os.path.join(copy, ds.keys()[0])
            with open(path, "a") as f:
                f.write(" ")
            with self.assertRaises(nsgraph.DataError) as e:
                ds[0]
            self.assertIn(ds.keys()[0], str(e.exception))
            with self.assertRaises(nsgraph.DataError):
                nsgraph.frames.Dataset(copy, "tst")
        finally:
            shutil.rmtree(tmp, ignore_errors=True)

    def test_collate_pads_centerlines_and_stacks_cameras(self):
        ds = nsgraph.frames.Dataset(self.root, "test", images=True)
        batch = nsgraph.torch.collate_frames([ds[0], ds[1]])
        b, n, p, _ = batch["centerlines"].shape
        self.assertEqual((b, p), (2, 11))
        self.assertEqual(n, max(len(ds[0]["centerlines"]), len(ds[1]["centerlines"])))
        self.assertEqual(batch["centerline_mask"].sum().item(), len(ds[0]["centerlines"]) + len(ds[1]["centerlines"]))
        c = len(ds[0]["cameras"])
        self.assertEqual(tuple(batch["K"].shape), (2, c, 3, 3))
        self.assertEqual(tuple(batch["extrinsic"].shape), (2, c, 4, 4))
        self.assertEqual(batch["images"].shape[:3], (2, c, 3))
        self.assertEqual(tuple(batch["topology"].shape), (2, n, n))

    def test_score_frames_and_the_frames_phase(self):
        ds = nsgraph.frames.Dataset(self.root, "test")
        results = copy_results(ds)
        report = nsgraph.score_frames(self.root, results, split="test")
        self.assertEqual((report["DET_l"], report["TOP_ll"], report["lane_score"]), (1.0, 1.0, 1.0))
        self.assertEqual(report["counts"]["frames"], len(ds))
        path = os.path.join(self.tmp, "results.json")
        with open(path, "w") as f:
            json.dump(results, f)
        out = nsgraph.evaluate(self.root, path, "frames-test")
        self.assertEqual(out["submission_result"]["DET_l"], 1.0)
        self.assertEqual(out["submission_result"]["n_frames"], len(ds))
        cli = json.loads(fixtures.run_nsgraph("score", "--quiet", "--frames", "--ground-truth", self.root,
                                              "--submission", path).stdout)
        self.assertEqual(cli, report)
        bad = copy_results(ds)
        next(iter(bad["results"].values()))["predictions"]["lane_centerline"][0]["confidence"] = float("nan")
        with self.assertRaises(nsgraph.SubmissionError) as e:
            nsgraph.score_frames(self.root, bad)
        self.assertTrue(any(i["check"] in ("submission.json", "frames.results.finite") for i in e.exception.issues))

    def test_render_draws_every_camera_and_the_bev(self):
        ds = nsgraph.frames.Dataset(self.root, "test")
        item = ds[0]
        out = os.path.join(self.tmp, "render")
        done = nsgraph.frames.render(self.root, item["token"], out)
        self.assertEqual(sorted(done["truth_pieces_in_image"]), sorted(item["cameras"]))
        self.assertEqual(set(os.listdir(out)), set(done["files"]))
        self.assertIn("bev.png", done["files"])
        self.assertGreater(sum(done["truth_pieces_in_image"].values()), 0)  # the lanes are in view somewhere
        ident = "/".join(["test", item["scene"], str(item["timestamp"])])
        with self.assertRaises(nsgraph.ConfigError):  # an earlier render: replaced only when asked
            nsgraph.frames.render(self.root, ident, out)
        again = nsgraph.frames.render(self.root, ident, out, overwrite=True)
        self.assertEqual(again["files"], done["files"])

    def test_openlanev2_results_dicts_score_as_they_are(self):
        """A TopoNet-style results dict: identifier tuple keys, float32 point arrays, numpy
        topology and confidences, OpenLane-V2's extra keys; the same report as the token-keyed
        JSON, through the Python call, to_results_json and the CLI."""
        ds = nsgraph.frames.Dataset(self.root, "test")
        by_token = nsgraph.score_frames(self.root, copy_results(ds), split="test")
        results, conf = {}, np.float32(0.999)
        for i in range(len(ds)):
            item = ds[i]
            lanes = [{"id": k, "points": c.astype(np.float32), "confidence": np.float32(conf - np.float32(1e-4) * k)}
                     for k, c in enumerate(item["centerlines"])]
            n = len(lanes)
            results[(item["split"], item["scene"], str(item["timestamp"]))] = {"predictions": {
                "lane_centerline": lanes, "traffic_element": [],
                "topology_lclc": item["topology"].astype(np.float64), "topology_lcte": np.zeros((n, 0))}}
        olv2 = {"method": "copy", "e-mail": "-", "institution / company": "-", "country / region": "-",
                "authors": [], "results": results}
        report = nsgraph.score_frames(self.root, olv2, split="test")
        self.assertEqual((report["DET_l"], report["TOP_ll"]), (1.0, 1.0))
        self.assertEqual(report["counts"], by_token["counts"])
        doc = nsgraph.frames.from_openlanev2(olv2)
        key = next(iter(doc["results"]))
        self.assertEqual(key.count("/"), 2)
        self.assertTrue(key.startswith("test/"))
        self.assertIsInstance(doc["results"][key]["predictions"]["lane_centerline"][0]["points"], list)
        path = nsgraph.frames.to_results_json(olv2, os.path.join(self.tmp, "olv2-results.json"))
        self.assertEqual([f for f in os.listdir(self.tmp) if f.endswith(".tmp")], [])
        cli = json.loads(fixtures.run_nsgraph("score", "--quiet", "--frames", "--ground-truth", self.root,
                                              "--submission", path).stdout)
        self.assertEqual(cli, report)
        # float32 confidences reach the file exactly (widened, not rounded to 17 digits' float64)
        first = next(iter(results.values()))["predictions"]["lane_centerline"][0]
        self.assertEqual(doc["results"][key]["predictions"]["lane_centerline"][0]["confidence"],
                         float(first["confidence"]))
        # LaneSegNet-style: lane segments (float32 lines) and topology_lsls only, as a dict.
        segs = {}
        for i in range(len(ds)):
            ann = ds.record(i)["annotation"]
            n = len(ann["lane_segment"])
            segs[(ds[i]["split"], ds[i]["scene"], str(ds[i]["timestamp"]))] = {"predictions": {
                "lane_segment": [dict({k: s[k].astype(np.float32) for k in ("centerline", "left_laneline",
                                                                             "right_laneline")},
                                      id=k, confidence=np.float32(0.9 - 1e-4 * k))
                                 for k, s in enumerate(ann["lane_segment"])],
                "area": [], "traffic_element": [], "topology_lsls": ann["topology_lsls"].astype(np.float64),
                "topology_lste": np.zeros((n, 0)), "lane_segment_1.0_idx_match_gt": np.full(n, np.nan)}}
        ls = nsgraph.score_frames(self.root, {"results": segs}, split="test")
        self.assertIsNone(ls["DET_l"])  # no centerlines submitted
        self.assertEqual((ls["lane_segments"]["DET_ls"], ls["lane_segments"]["TOP_lsls"]), (1.0, 1.0))
        self.assertEqual(ls["lane_segments"]["DET_a"], 0.0)  # no area predicted
        # A leaderboard's evaluate (EvalAI form) shows the lane-segment track's columns.
        seg_file = nsgraph.frames.to_results_json({"results": segs}, os.path.join(self.tmp, "segments.json"))
        board = nsgraph.hosting.evaluate(self.root, seg_file, "frames-test")["submission_result"]
        self.assertIsNone(board["DET_l"])
        self.assertEqual((board["DET_ls"], board["TOP_lsls"], board["DET_a"]), (1.0, 1.0, 0.0))
        self.assertAlmostEqual(board["ls_score"], ls["lane_segments"]["score"])
        # A frame named twice, by its token and by its identifier: refused, both keys named.
        token = ds[0]["token"]
        twice = dict(doc, results=dict(doc["results"]))
        twice["results"][token] = copy_results(ds)["results"][token]
        with self.assertRaises(nsgraph.SubmissionError) as e:
            nsgraph.score_frames(self.root, twice)
        self.assertTrue(any(i["check"] == "frames.results.duplicate" for i in e.exception.issues), e.exception.issues)
        # Keys and values that are no results: named, not crashed on.
        for bad in ({"results": {("test", "scene-1"): {}}}, {"results": {("test", "a/b", "1"): {}}},
                    {"results": {key: {"predictions": {"lane_centerline": [{"points": np.array(["x"])}]}}}},
                    {"results": {key: {"predictions": {"lane_centerline": [{"points": [[0, 0, 0]],
                                                                             "confidence": np.float32("nan")}]}}}},
                    {"results": [1, 2]}):
            with self.assertRaises(nsgraph.SubmissionError, msg=repr(bad)):
                nsgraph.frames.from_openlanev2(bad)


def record_doc(split="test"):
    """A record as `nsgraph frames` writes it: one camera, two centerlines, the first linked
    to the second (tests/data/frames/record-two-lanes.json, also a fuzz seed)."""
    with open(os.path.join(fixtures.SOURCE_DIR, "tests", "data", "frames", "record-two-lanes.json")) as f:
        record = json.load(f)
    record["split"] = split
    return record


RECORD = "test/scene-0001/info/1.json"


def write_export(root, record_text=None, change=None):
    """A one-record export: the record (text) listed with its size and sha256; `change(manifest)`
    edits the manifest before it is written. Returns the manifest's path."""
    data = (record_text if record_text is not None else json.dumps(record_doc())).encode()
    os.makedirs(os.path.join(root, os.path.dirname(RECORD)), exist_ok=True)
    with open(os.path.join(root, RECORD), "wb") as f:
        f.write(data)
    manifest = {"schema_version": "1", "kind": "nsgraph-frames", "tool_version": "test",
                "source": {"dataset": "d", "dataset_manifest_sha256": "2" * 64, "dataroot": "release",
                           "version": "v1.0-mini", "split_buffer_m": 10.0},
                "config": {"window": {"x_min_m": -50.0, "x_max_m": 50.0, "y_min_m": -25.0, "y_max_m": 25.0},
                           "centerline_points": 11, "copy_images": False},
                "layout": {"records": "", "images": "", "traffic_elements": ""}, "counts": {},
                "files": [{"path": RECORD, "bytes": len(data), "sha256": hashlib.sha256(data).hexdigest()}]}
    if change:
        change(manifest)
    path = os.path.join(root, "manifest.json")
    with open(path, "w") as f:
        json.dump(manifest, f)
    return path


class FramesHostileTest(unittest.TestCase):
    """Crafted exports through nsgraph.frames.Dataset: the library's reader (the one the CLI
    uses) names file, JSON pointer and expectation; nothing outside the export is read, nothing
    is read unbounded, no RecursionError / KeyError / ValueError escapes."""

    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="nsg-py-frames-hostile-")

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def export(self, name, **kwargs):
        root = os.path.join(self.tmp, name)
        write_export(root, **kwargs)
        return root

    def test_the_crafted_export_reads(self):
        root = self.export("ok")
        ds = nsgraph.frames.Dataset(root, "test")
        self.assertEqual(len(ds), 1)
        item = ds[0]
        self.assertEqual(item["token"], "tok")
        self.assertEqual(item["centerlines"][1].shape, (11, 3))
        np.testing.assert_array_equal(item["topology"], [[0, 1], [0, 0]])
        np.testing.assert_array_equal(item["pose"][:3, 3], [600.0, 1600.0, 0.0])
        # source.dataroot ("release") is relative to the export's folder.
        self.assertEqual(item["cameras"]["CAM_FRONT"]["image_path"],
                         os.path.join(root, "release", "samples/CAM_FRONT/x.jpg"))

    def test_paths_outside_the_export_are_refused_by_name(self):
        outside = os.path.join(self.tmp, "outside", "info")
        os.makedirs(outside)
        text = json.dumps(record_doc())
        with open(os.path.join(outside, "1.json"), "w") as f:
            f.write(text)
        for path in ("test/../../outside/info/1.json", os.path.join(outside, "1.json")):
            root = self.export("escape", change=lambda m, p=path: m["files"][0].update(path=p))
            with self.assertRaises(nsgraph.ParseError) as e:
                nsgraph.frames.Dataset(root, "test")
            self.assertEqual(e.exception.file, os.path.join(root, "manifest.json"))
            self.assertEqual(e.exception.record, "/files/0/path")
            self.assertIn("inside the export", e.exception.expected)

    def test_a_record_is_measured_before_it_is_read(self):
        zero = self.export("zero")
        os.remove(os.path.join(zero, RECORD))
        os.symlink("/dev/zero", os.path.join(zero, RECORD))
        started = time.monotonic()
        with self.assertRaises(nsgraph.DataError) as e:
            nsgraph.frames.Dataset(zero, "test")[0]
        self.assertIn("symbolic link", str(e.exception))
        self.assertEqual(e.exception.file, os.path.join(zero, RECORD))
        self.assertLess(time.monotonic() - started, 5.0)
        # 1 GiB (sparse) listed as a few KiB: refused by its size, not read.
        big = self.export("big")
        os.truncate(os.path.join(big, RECORD), 1 << 30)
        before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        with self.assertRaises(nsgraph.DataError) as e:
            nsgraph.frames.Dataset(big, "test")[0]
        self.assertIn("size", e.exception.expected)
        self.assertLess(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before, 256 * 1024)  # KiB

    def test_crafted_documents_raise_the_packages_errors_as_the_cli_reports_them(self):
        no_pose = record_doc()
        del no_pose["pose"]
        point_string = record_doc()
        point_string["annotation"]["lane_centerline"][0]["points"][2] = "x"
        cases = {
            "no-pose": (dict(record_text=json.dumps(no_pose)), nsgraph.ParseError, "/pose"),
            "deep": (dict(record_text="[" * 100000 + "]" * 100000), nsgraph.ParseError, ""),
            "point-string": (dict(record_text=json.dumps(point_string)), nsgraph.ParseError,
                             "/annotation/lane_centerline/0/points/2"),
            "bytes-string": (dict(change=lambda m: m["files"][0].update(bytes="100")), nsgraph.ParseError,
                             "/files/0/bytes"),
            "sha256-number": (dict(change=lambda m: m["files"][0].update(sha256=7)), nsgraph.ParseError,
                              "/files/0/sha256"),
            "files-object": (dict(change=lambda m: m.update(files={})), nsgraph.ParseError, "/files"),
            "no-kind": (dict(change=lambda m: m.pop("kind")), nsgraph.ParseError, "/kind"),
            "no-source": (dict(change=lambda m: m.pop("source")), nsgraph.ParseError, "/source"),
        }
        results = os.path.join(self.tmp, "results.json")
        with open(results, "w") as f:
            f.write('{"results": {}}')
        for name, (kwargs, error, pointer) in cases.items():
            with self.subTest(name):
                root = self.export(name, **kwargs)
                with self.assertRaises(error) as e:
                    nsgraph.frames.Dataset(root, "test")[0]
                self.assertEqual(e.exception.record, pointer)
                self.assertTrue(e.exception.file.startswith(root))
                self.assertTrue(e.exception.expected)
                cli = fixtures.run_nsgraph("score", "--quiet", "--frames", "--ground-truth", root, "--submission",
                                           results, check=False)
                self.assertEqual(cli.returncode, 2, cli.stderr)
                self.assertIn(str(e.exception), cli.stderr)

    def test_max_seconds_bounds_the_frames_phase(self):
        golden = os.path.join(fixtures.SOURCE_DIR, "tests", "data", "golden", "frames")
        gt, pred = os.path.join(golden, "gt.json"), os.path.join(golden, "pred.json")
        with self.assertRaises(nsgraph.ConfigError) as e:
            nsgraph.evaluate(gt, pred, "frames-test", max_seconds=1e-9)
        self.assertEqual(e.exception.record, "--max-seconds")
        with self.assertRaises(nsgraph.ConfigError):
            nsgraph.score_frames(gt, pred, max_seconds=1e-9)
        self.assertIn("DET_l", nsgraph.evaluate(gt, pred, "frames-test", max_seconds=0)["submission_result"])


if __name__ == "__main__":
    unittest.main()

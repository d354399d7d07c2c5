"""nsgraph.frames: the records of an export (through its manifest), images decoded on
demand, the PyTorch collate, score_frames (= nsgraph score --frames) and evaluate's frames
phase, on the e2e dataset's frames."""
import json
import os
import shutil
import tempfile
import unittest

import numpy as np

import fixtures
import nsgraph
import nsgraph.frames

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


if __name__ == "__main__":
    unittest.main()

"""OpenLane-V2's own code on nsgraph's frames (optional: its source is not a Debian package).

With NSG_OPENLANEV2 set to a checkout of github:OpenDriveLab/OpenLane-V2 (f085b3d was used;
Debian's python3-scipy, python3-shapely and python3-tqdm installed), this runs, on the e2e
dataset's frames export:
- its preprocessing `collect()` on the export's data_dict.json → the collection pickle, read
  back by its `Collection`/`Frame`: every record of every split present, centerlines and
  topology as nsgraph's reader gives them;
- its evaluator's `evaluate()` on a TopoNet-style results dict (identifier tuple keys, float32
  arrays, tied confidences: every lane 0.9, more than 16 per frame in places) against
  `nsgraph.score_frames` of the same dict: DET_l and TOP_ll to 1e-6;
- its lane-segment `collect()` (v2.1) on the export's version-2 records, each given the
  `<timestamp>-ls.json` name that collect reads: the lane segments and areas it resamples are
  the ones nsgraph's scorer takes as ground truth (the points to float32 rounding).
The evaluator is imported as tests/data/golden/frames/make_golden.py imports it (the same
stand-ins for the packages Debian lacks). Without NSG_OPENLANEV2 every test skips as
optional; the committed goldens hold the same rules in every run."""
import importlib
import json
import os
import shutil
import sys
import tempfile
import unittest

import numpy as np

import fixtures
import nsgraph
import nsgraph.frames
from test_frames import export

OPENLANEV2 = os.environ.get("NSG_OPENLANEV2", "")


def _evaluator():
    sys.path.insert(0, os.path.join(fixtures.SOURCE_DIR, "tests", "data", "golden", "frames"))
    try:
        import make_golden
    finally:
        sys.path.pop(0)
    return make_golden.import_evaluator(OPENLANEV2)


@unittest.skipUnless(OPENLANEV2, "optional peer: set NSG_OPENLANEV2 to an OpenLane-V2 checkout")
class OpenLaneV2Test(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        try:
            import scipy  # noqa: F401  (the evaluator's distances)
            import shapely  # noqa: F401  (imported by collect)
            import tqdm  # noqa: F401
        except ImportError as e:
            raise unittest.SkipTest(f"optional peer OpenLane-V2 needs python3-scipy/-shapely/-tqdm: {e}")
        cls.ev = _evaluator()
        cls.tmp = tempfile.mkdtemp(prefix="nsg-py-olv2-")
        cls.root = export(cls.tmp)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_collect_and_collection_read_the_export(self):
        collect = importlib.import_module("openlanev2.centerline.preprocessing").collect
        Collection = importlib.import_module("openlanev2.centerline.dataset").Collection
        copy = os.path.join(self.tmp, "copy")  # collect() writes its pickle into the root
        shutil.copytree(self.root, copy)
        with open(os.path.join(copy, "data_dict.json")) as f:
            data_dict = json.load(f)
        for split in data_dict:
            ds = nsgraph.frames.Dataset(self.root, split)
            collect(copy, {split: data_dict[split]}, f"nsg_{split}")
            collection = Collection(copy, copy, f"nsg_{split}")
            self.assertEqual(len(collection.keys), len(ds))
            for i in range(len(ds)):
                item = ds[i]
                frame = collection.get_frame_via_identifier((split, item["scene"], str(item["timestamp"])))
                lanes = frame.get_annotations_lane_centerlines()
                self.assertEqual(len(lanes), len(item["centerlines"]))
                for lane, ours in zip(lanes, item["centerlines"]):
                    np.testing.assert_array_equal(lane["points"], ours)
                np.testing.assert_array_equal(frame.get_annotations()["topology_lclc"], item["topology"])

    def test_evaluator_and_score_frames_agree_on_a_results_dict_with_ties(self):
        ds = nsgraph.frames.Dataset(self.root, "test")
        rnd = np.random.default_rng(3)
        results, gt = {}, {}
        for i in range(len(ds)):
            item = ds[i]
            key = ("test", item["scene"], str(item["timestamp"]))
            gt[key] = {"annotation": {
                "lane_centerline": [{"id": k, "points": c} for k, c in enumerate(item["centerlines"])],
                "traffic_element": [], "topology_lclc": item["topology"].astype(np.int8),
                "topology_lcte": np.zeros((len(item["centerlines"]), 0), dtype=np.int8)}}
            lanes = []
            for k, c in enumerate(item["centerlines"]):
                moved = c + np.float32(rnd.uniform(0.0, 2.9)) * np.array([1, 0, 0], dtype=np.float32)
                lanes.append({"id": k, "points": moved.astype(np.float32), "confidence": np.float32(0.9)})
            n = len(lanes)
            results[key] = {"predictions": {"lane_centerline": lanes, "traffic_element": [],
                                            "topology_lclc": item["topology"].astype(np.float64),
                                            "topology_lcte": np.zeros((n, 0))}}
        olv2 = {"method": "ties", "e-mail": "-", "institution / company": "-", "country / region": "-",
                "authors": [], "results": results}
        theirs = self.ev.evaluate(gt, olv2, verbose=False)["OpenLane-V2 Score"]
        ours = nsgraph.score_frames(self.root, olv2, split="test")
        self.assertAlmostEqual(ours["DET_l"], float(theirs["DET_l"]), delta=1e-6)
        self.assertAlmostEqual(ours["TOP_ll"], float(theirs["TOP_ll"]), delta=1e-6)

    def test_lane_segment_collect_reads_the_version_2_records(self):
        collect = importlib.import_module("openlanev2.lanesegment.preprocessing").collect
        copy = os.path.join(self.tmp, "copy-ls")
        shutil.copytree(self.root, copy)
        with open(os.path.join(copy, "data_dict.json")) as f:
            data_dict = json.load(f)
        for split, scenes in data_dict.items():
            for scene, names in scenes.items():
                for name in names:
                    info = os.path.join(copy, split, scene, "info")
                    shutil.copyfile(os.path.join(info, name), os.path.join(info, name[:-5] + "-ls.json"))
        collect(copy, {"test": data_dict["test"]}, "nsg_ls",
                n_points={"area": 20, "centerline": 10, "left_laneline": 10, "right_laneline": 10})
        import pickle  # their collection; our own file, read back in this test only
        with open(os.path.join(copy, "nsg_ls.pkl"), "rb") as f:
            meta = pickle.load(f)
        ds = nsgraph.frames.Dataset(self.root, "test")
        self.assertEqual(len(meta), len(ds))
        segments = 0
        for i in range(len(ds)):
            record = ds.record(i)
            theirs = meta[("test", record["segment_id"], str(record["timestamp"]))]["annotation"]
            ours = record["annotation"]
            self.assertEqual(len(theirs["lane_segment"]), len(ours["lane_segment"]))
            for t, o in zip(theirs["lane_segment"], ours["lane_segment"]):
                for line in ("centerline", "left_laneline", "right_laneline"):
                    self.assertEqual(t[line].shape, (10, 3))
                    # Our 10 points resampled again: the same points within the chords' shortening.
                    np.testing.assert_allclose(t[line], o[line], atol=0.05)
                segments += 1
            self.assertEqual([a["category"] for a in theirs["area"]], [a["category"] for a in ours["area"]])
            np.testing.assert_array_equal(theirs["topology_lsls"], ours["topology_lsls"])
        self.assertGreater(segments, 0)


if __name__ == "__main__":
    unittest.main()

"""nsgraph.torch: tensors, a DataLoader with 2 workers, collate, seeded augmentations that
move graphs and headings with the rasters."""
import math
import unittest

import numpy as np
import torch

import fixtures
import nsgraph
import nsgraph.torch as ntorch


def heading_vector(h):
    """Unit vector (du, dv) of a heading h (bearing clockwise from north / 2π); v grows south."""
    theta = 2 * math.pi * h
    return np.array([math.sin(theta), -math.cos(theta)])


def synthetic_tile(size=8):
    """A tile with a vehicle of heading 0.1 at (row 2, col 5) and a graph edge from that
    pixel to (row 2, col 6)."""
    vehicle = np.full((size, size), -1.0, dtype=np.float32)
    vehicle[2, 5] = 0.1
    lidar = np.zeros((size, size), dtype=np.uint8)
    lidar[2, 5] = 200
    return {"key": "t", "lidar": lidar, "rgb": np.zeros((size, size, 3), np.uint8), "vehicle": vehicle,
            "semantic": np.full((size, size), 255, np.uint8), "coverage": (lidar > 0).astype(np.uint8),
            "graph": {"nodes_px": np.array([[5.0, 2.0], [6.0, 2.0]]), "nodes_m": np.zeros((2, 2)),
                      "edges": np.array([[0, 1]]), "lane_tokens": ["L"]}}


class GeometryTest(unittest.TestCase):
    def check(self, op):
        tile = synthetic_tile()
        ntorch._transform(tile, op)
        # the graph node still sits on the LiDAR return and the vehicle
        u, v = tile["graph"]["nodes_px"][0].astype(int)
        self.assertEqual(tile["lidar"][v, u], 200, op)
        self.assertGreaterEqual(tile["vehicle"][v, u], 0.0, op)
        # the heading turned like the image: compare with the edge direction, which moved
        # with the nodes (the edge pointed east, the heading 0.1 is 36° east of north)
        before = heading_vector(0.1)
        edge = np.diff(tile["graph"]["nodes_px"], axis=0)[0]
        east = np.array([1.0, 0.0])
        # the map applied to vectors, from where "east" went
        if op == "flip_u":
            m = np.array([[-1, 0], [0, 1]])
        elif op == "flip_v":
            m = np.array([[1, 0], [0, -1]])
        else:
            m = np.array([[0, 1], [-1, 0]])
        np.testing.assert_allclose(m @ east, edge)
        np.testing.assert_allclose(heading_vector(float(tile["vehicle"][v, u])), m @ before, atol=1e-6)
        self.assertEqual(int((tile["vehicle"] >= 0).sum()), 1)

    def test_flips_and_quarter_turns_move_graph_and_headings_consistently(self):
        for op in ("flip_u", "flip_v", "rot90"):
            self.check(op)

    def test_a_mirror_turns_left_into_right_and_a_quarter_turn_keeps_turns(self):
        left, right, straight = (nsgraph.TURNS.index(t) for t in ("left", "right", "straight"))
        for op, want in (("flip_u", [right, left, straight]), ("flip_v", [right, left, straight]),
                         ("rot90", [left, right, straight])):
            tile = synthetic_tile()
            tile["graph"]["turn"] = np.array([left, right, straight])
            ntorch._transform(tile, op)
            self.assertEqual(tile["graph"]["turn"].tolist(), want, op)

    def test_four_quarter_turns_are_the_identity(self):
        tile = synthetic_tile()
        for _ in range(4):
            ntorch._transform(tile, "rot90")
        ref = synthetic_tile()
        np.testing.assert_array_equal(tile["lidar"], ref["lidar"])
        np.testing.assert_allclose(tile["vehicle"], ref["vehicle"], atol=1e-6)
        np.testing.assert_allclose(tile["graph"]["nodes_px"], ref["graph"]["nodes_px"])


class TorchDatasetTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.root = fixtures.e2e_dataset("tar")

    def test_samples_are_tensors(self):
        ds = ntorch.TorchDataset(self.root, "test")
        s = ds[0]
        tile = nsgraph.Dataset(self.root, "test")[0]
        self.assertEqual(s["lidar"].dtype, torch.uint8)
        self.assertEqual(tuple(s["rgb"].shape), (3,) + tile["lidar"].shape)
        self.assertTrue(torch.equal(s["rgb"], torch.from_numpy(tile["rgb"]).permute(2, 0, 1)))
        self.assertEqual(s["vehicle"].dtype, torch.float32)
        self.assertEqual(s["edges"].dtype, torch.int64)
        np.testing.assert_allclose(s["nodes_m"].numpy(), tile["graph"]["nodes_m"], atol=1e-6)

    def test_dataloader_with_two_workers_iterates_every_tile(self):
        ds = ntorch.TorchDataset(self.root, "train", augment=ntorch.Augment(
            dropout={"rgb": 0.3, "semantic": 0.3}, brightness=0.1, contrast=0.1, flips=True, rot90=True), seed=3)
        loader = torch.utils.data.DataLoader(ds, batch_size=3, num_workers=2, collate_fn=ntorch.collate)
        keys, nodes = [], 0
        for batch in loader:
            keys += batch["key"]
            b = len(batch["key"])
            self.assertEqual(tuple(batch["lidar"].shape[:1]), (b,))
            self.assertEqual(int(batch["num_nodes"].sum()), batch["nodes"].shape[0])
            self.assertEqual(batch["node_batch"].shape[0], batch["nodes"].shape[0])
            nb = batch["node_batch"]
            if batch["edges"].numel():
                # offsets: every edge joins two nodes of the same sample
                self.assertTrue(torch.equal(nb[batch["edges"][:, 0]], nb[batch["edges"][:, 1]]))
            # the attributes concatenate with their nodes and edges, lane changes offset like edges
            self.assertEqual(batch["junction"].shape[0], batch["nodes"].shape[0])
            self.assertEqual(batch["turn"].shape[0], batch["edges"].shape[0])
            self.assertEqual(batch["connector"].dtype, torch.bool)
            self.assertEqual(int(batch["num_lane_changes"].sum()), batch["lane_changes"].shape[0])
            if batch["lane_changes"].numel():
                self.assertTrue(torch.equal(nb[batch["lane_changes"][:, 0]], nb[batch["lane_changes"][:, 1]]))
            nodes += batch["nodes"].shape[0]
        self.assertEqual(keys, nsgraph.Dataset(self.root, "train", modalities=()).keys)
        self.assertGreater(nodes, 0)
        # the same seed and epoch give the same tensors, in the main process as in workers:
        # every batch, every field
        again = list(torch.utils.data.DataLoader(ds, batch_size=3, num_workers=0, collate_fn=ntorch.collate))
        workers = list(loader)
        self.assertEqual(len(workers), len(again))
        for i, (w, m) in enumerate(zip(workers, again)):
            self.assertEqual(sorted(w), sorted(m))
            for field in w:
                if torch.is_tensor(w[field]):
                    self.assertTrue(torch.equal(w[field], m[field]), f"batch {i}, {field}")
                else:
                    self.assertEqual(w[field], m[field], f"batch {i}, {field}")
        ds.set_epoch(1)
        self.assertFalse(all(torch.equal(ds[i]["lidar"], again[0]["lidar"][i]) for i in range(3)))

    def test_dropout_clears_the_input_and_its_coverage_bit(self):
        aug = ntorch.Augment(dropout={"lidar": 1.0})
        tile = nsgraph.Dataset(self.root, "test")[0]
        aug(tile, np.random.default_rng(0))
        self.assertFalse(tile["lidar"].any())
        self.assertFalse((tile["coverage"] & 1).any())

    def test_jitter_keeps_no_data_pixels(self):
        tile = nsgraph.Dataset(self.root, "test")[0]
        empty = tile["lidar"] == 0
        ntorch.Augment(brightness=0.5, contrast=0.5)(tile, np.random.default_rng(1))
        np.testing.assert_array_equal(tile["lidar"] == 0, empty)


if __name__ == "__main__":
    unittest.main()

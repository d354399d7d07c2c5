"""nsgraph.graphify: a mask drawn from a known graph back to that graph (scored with
nsgraph.score_tile), arrays and files give one graph, bad input raises naming the file."""
import os
import tempfile
import unittest

import numpy as np

import nsgraph


def two_lanes_mask():
    """Two parallel lanes 17.5 px (3.5 m) apart, 7 px wide, on a 256 x 256 tile, and
    their ground truth (one polyline each)."""
    mask = np.zeros((256, 256), np.uint8)
    rows = np.arange(256)[:, None]
    for v in (119.25, 136.75):
        mask[(np.abs(rows - v) <= 3.5) & (np.arange(256)[None, :] >= 16) & (np.arange(256)[None, :] <= 240)] = 255
    us = np.linspace(16, 240, 9)
    nodes = [[u, 119.25] for u in us] + [[u, 136.75] for u in us]
    edges = [[k, k + 1] for k in range(8)] + [[9 + k, 10 + k] for k in range(8)]
    return mask, (np.array(nodes), np.array(edges))


class GraphifyTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()

    def tearDown(self):
        self.tmp.cleanup()

    def test_a_drawn_graph_comes_back(self):
        mask, truth = two_lanes_mask()
        g = nsgraph.graphify(mask)
        self.assertEqual(sorted(g), ["edge_scores", "edges", "node_scores", "nodes"])
        self.assertEqual(g["node_scores"].shape, (len(g["nodes"]),))
        self.assertEqual(g["edge_scores"].shape, (len(g["edges"]),))
        self.assertGreaterEqual(g["node_scores"].min(), 0.99)  # a clean mask: ~1 under every anchor
        self.assertEqual(g["nodes"].dtype, np.float64)
        self.assertEqual(g["edges"].dtype, np.int64)
        self.assertEqual(g["nodes"].shape[1], 2)
        # Undirected: every edge also runs the other way.
        edges = {tuple(e) for e in g["edges"].tolist()}
        self.assertEqual(edges, {(b, a) for a, b in edges})
        self.assertGreaterEqual(nsgraph.score_tile(truth, g)["apls"], 0.95)

    def test_arrays_files_and_dtypes_agree(self):
        mask, _ = two_lanes_mask()
        g = nsgraph.graphify(mask)
        path = os.path.join(self.tmp.name, "tile.npy")
        np.save(path, (mask / 255.0).astype(np.float32))
        for other in (nsgraph.graphify(mask > 0), nsgraph.graphify(path),
                      nsgraph.graphify((mask.astype(np.uint16) * 257))):
            np.testing.assert_array_equal(other["edges"], g["edges"])
            np.testing.assert_allclose(other["nodes"], g["nodes"])

    def test_a_heading_map_directs_the_edges(self):
        # The upper lane runs east (a quarter turn clockwise from north), the lower west;
        # the truth's second polyline runs east too, so flip it to west.
        mask, (nodes, edges) = two_lanes_mask()
        edges = np.concatenate([edges[:8], edges[8:][:, ::-1]])
        heading = np.full((256, 256), -1.0, np.float32)
        heading[mask > 0] = np.where(np.arange(256)[:, None] < 128, 0.25, 0.75).repeat(256, 1)[mask > 0]
        g = nsgraph.graphify(mask, heading=heading)
        directed = {tuple(e) for e in g["edges"].tolist()}
        self.assertFalse(directed & {(b, a) for a, b in directed})
        self.assertGreaterEqual(nsgraph.score_tile((nodes, edges), g)["apls_directed"], 0.95)
        path = os.path.join(self.tmp.name, "heading.npy")
        np.save(path, heading)
        np.testing.assert_array_equal(nsgraph.graphify(mask, heading=path)["edges"], g["edges"])
        with self.assertRaises(nsgraph.DataError) as e:
            nsgraph.graphify(mask, heading=heading[:100])
        self.assertIn("the size of its map", str(e.exception))

    def test_options_are_the_declared_keys(self):
        mask, _ = two_lanes_mask()
        sparse = nsgraph.graphify(mask, anchor_spacing_px=40)
        self.assertLess(len(sparse["nodes"]), len(nsgraph.graphify(mask)["nodes"]))
        with self.assertRaises(nsgraph.ConfigError) as e:
            nsgraph.graphify(mask, treshold=0.3)
        self.assertIn("threshold", str(e.exception))
        with self.assertRaises(nsgraph.ConfigError):
            nsgraph.graphify(mask, threshold=1.5)

    def test_bad_input_raises_naming_it(self):
        with self.assertRaises(nsgraph.DataError):
            nsgraph.graphify(np.zeros((4, 4, 3), np.uint8))
        with self.assertRaises(nsgraph.DataError):
            nsgraph.graphify(np.zeros((4, 4), np.int64))
        cube = os.path.join(self.tmp.name, "cube.npy")
        np.save(cube, np.zeros((2, 4, 4), np.float32))
        with self.assertRaises(nsgraph.DataError) as e:
            nsgraph.graphify(cube)
        self.assertIn(cube, str(e.exception))
        missing = os.path.join(self.tmp.name, "missing.png")
        with self.assertRaises(nsgraph.IoError) as e:
            nsgraph.graphify(missing)
        self.assertIn(missing, str(e.exception))


if __name__ == "__main__":
    unittest.main()

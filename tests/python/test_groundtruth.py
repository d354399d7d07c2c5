"""nsgraph.adaptive_ground_truth on hand-made graphs where the answer is known."""
import unittest

import numpy as np

import nsgraph

# Metres, y north. Lane A (0,0)→(10,0)→(20,0) forks at node 2 into B (north to (20,10)) and
# C (east to (30,0)); D (0,20)→(20,20) stands alone; E continues B north to (20,30).
NODES = np.array([[0, 0], [10, 0], [20, 0], [20, 10], [30, 0], [0, 20], [20, 20], [20, 30]], dtype=float)
EDGES = np.array([[0, 1], [1, 2], [2, 3], [2, 4], [5, 6], [3, 7]])
TOKENS = ["A", "A", "B", "C", "D", "E"]
GRAPH = {"nodes_m": NODES, "nodes_px": NODES / 0.2, "edges": EDGES, "lane_tokens": TOKENS}


def projected(result):
    return {int(i): (tuple(p), t) for i, p, t in zip(result["input"], result["points"], result["lane_tokens"])}


class AdaptiveGroundTruthTest(unittest.TestCase):
    def test_projection_order_and_joins(self):
        proposals = [[15, 1.0], [5, -0.5], [21, 6], [25, -0.3], [10, 19], [10, 10], [12, 0.2]]
        r = nsgraph.adaptive_ground_truth(GRAPH, proposals, frame="m")
        # orthogonal projection onto the nearest lane segment; (10, 10) is > 4 m from every lane
        self.assertEqual(projected(r), {0: ((15.0, 0.0), "A"), 1: ((5.0, 0.0), "A"), 2: ((20.0, 6.0), "B"),
                                        3: ((25.0, 0.0), "C"), 4: ((10.0, 20.0), "D"), 6: ((12.0, 0.0), "A")})
        np.testing.assert_allclose(r["distance"], [0.5, 0.2, 1.0, 1.0, 0.3, 1.0])
        # ordered by lane, then along it
        self.assertEqual(r["input"].tolist(), [1, 6, 0, 2, 3, 4])
        np.testing.assert_allclose(r["along"], [5, 12, 15, 6, 5, 10])
        self.assertEqual(r["edge"].tolist(), [0, 1, 1, 2, 3, 4])
        # consecutive points of a lane connected; A's last point to the first of B and of C
        self.assertEqual(r["edges"].tolist(), [[0, 1], [1, 2], [2, 3], [2, 4]])
        self.assertEqual(r["edges"].dtype, np.int64)

    def test_connections_pass_through_lanes_without_points(self):
        r = nsgraph.adaptive_ground_truth(GRAPH, [[5, 0.5], [20.5, 25]], frame="m")
        self.assertEqual(r["lane_tokens"], ["A", "E"])
        self.assertEqual(r["edges"].tolist(), [[0, 1]])  # through B (10 m), within 20 m
        short = nsgraph.adaptive_ground_truth(GRAPH, [[5, 0.5], [20.5, 25]], frame="m", max_follow=5.0)
        self.assertEqual(short["edges"].tolist(), [])

    def test_pixel_frame_scales_the_distances(self):
        proposals_m = np.array([[15, 1.0], [5, -0.5], [21, 6], [10, 10]])
        in_m = nsgraph.adaptive_ground_truth(GRAPH, proposals_m, frame="m")
        in_px = nsgraph.adaptive_ground_truth(GRAPH, proposals_m / 0.2, frame="px")
        np.testing.assert_allclose(in_px["points"] * 0.2, in_m["points"])
        self.assertEqual(in_px["edges"].tolist(), in_m["edges"].tolist())
        tight = nsgraph.adaptive_ground_truth(GRAPH, proposals_m / 0.2, frame="px", max_distance=3.0)
        self.assertEqual(tight["input"].tolist(), [1])  # only the one 0.5 m = 2.5 px away

    def test_a_lane_clipped_into_two_pieces_is_not_connected_across_the_gap(self):
        # one token, two chains (the lane leaves the tile and comes back)
        nodes = np.array([[0, 0], [10, 0], [30, 0], [40, 0]], dtype=float)
        graph = {"nodes_m": nodes, "edges": np.array([[0, 1], [2, 3]]), "lane_tokens": ["A", "A"]}
        r = nsgraph.adaptive_ground_truth(graph, [[2, 1], [8, 1], [32, 1], [38, 1]], frame="m")
        self.assertEqual(r["lane"].tolist(), [0, 0, 1, 1])
        self.assertEqual(r["edges"].tolist(), [[0, 1], [2, 3]])

    def test_lane_changes_are_lateral_links_not_connections(self):
        # Two parallel eastbound lanes 3.5 m apart, rungs both ways at every node.
        nodes = np.array([[0, 0], [10, 0], [20, 0], [0, 3.5], [10, 3.5], [20, 3.5]], dtype=float)
        rungs = [[0, 3], [3, 0], [1, 4], [4, 1], [2, 5], [5, 2]]
        graph = {"nodes_m": nodes, "edges": np.array([[0, 1], [1, 2], [3, 4], [4, 5]]),
                 "lane_tokens": ["A", "A", "B", "B"], "lane_changes": np.array(rungs)}
        r = nsgraph.adaptive_ground_truth(graph, [[4, 0.2], [11, -0.3], [9, 3.4]], frame="m")
        self.assertEqual(r["lane_tokens"], ["A", "A", "B"])
        self.assertEqual(r["edges"].tolist(), [[0, 1]])  # successors only: never across lanes
        # Nearest point at each node (on an edge there): node 0 -> 0, node 1 -> 1 (1 m, not 6),
        # node 2 -> 1, node 3 -> 2, node 4 -> 2, node 5 -> none; so rungs 2 <-> 5 link nothing.
        self.assertEqual(r["lane_changes"].tolist(), [[0, 2], [1, 2], [2, 0], [2, 1]])
        self.assertEqual(r["lane_changes"].dtype, np.int64)
        # A graph without lane changes has no lateral links.
        plain = nsgraph.adaptive_ground_truth(GRAPH, [[15, 1.0]], frame="m")
        self.assertEqual(plain["lane_changes"].shape, (0, 2))
        with self.assertRaises(nsgraph.DataError) as e:
            nsgraph.adaptive_ground_truth(dict(graph, lane_changes=[[0, 9]]), [[4, 0.2]], frame="m")
        self.assertIn("lane_changes[0]", str(e.exception))

    def test_a_dataset_tiles_lane_changes_reach_the_links(self):
        # On a generated tile: proposals at the ground truth's own nodes give one link per
        # lane change (each node its own nearest point), none of them among the connections.
        import fixtures
        ds = nsgraph.Dataset(fixtures.e2e_dataset("tar"), "test", modalities=())
        tile = max(ds, key=lambda t: len(t["graph"]["lane_changes"]))
        g = tile["graph"]
        r = nsgraph.adaptive_ground_truth(tile, g["nodes_px"], frame="px")
        self.assertGreater(len(r["lane_changes"]), 0)
        point_of = {int(i): k for k, i in enumerate(r["input"])}
        want = sorted({(point_of[int(s)], point_of[int(t)]) for s, t in g["lane_changes"]})
        self.assertEqual([tuple(p) for p in r["lane_changes"].tolist()], want)
        self.assertFalse({tuple(p) for p in r["lane_changes"].tolist()} & {tuple(p) for p in r["edges"].tolist()})

    def test_bad_input_names_the_problem(self):
        with self.assertRaises(nsgraph.DataError) as e:
            nsgraph.adaptive_ground_truth({"nodes_m": NODES, "edges": [[0, 99]], "lane_tokens": ["A"]}, [[0, 0]],
                                          frame="m")
        self.assertIn("edges[0]", str(e.exception))
        with self.assertRaises(nsgraph.ConfigError):
            nsgraph.adaptive_ground_truth(GRAPH, [[0, 0, 0]], frame="m")
        with self.assertRaises(nsgraph.ConfigError):
            nsgraph.adaptive_ground_truth(GRAPH, [[0, 0]], frame="m", max_distance=-1)


if __name__ == "__main__":
    unittest.main()

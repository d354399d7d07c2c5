// Junction TOPO and the per-class recalls (docs/metrics.md "Junction TOPO", "Per-class
// recall") on cases worked by hand. Samples every 2 px: a segment of L px has
// k = ceil(L/2 - 0.05) pieces, so k - 1 interior samples.
#include <gtest/gtest.h>

#include <cmath>

#include "nsg/core/error.h"
#include "nsg/metrics/measure.h"

namespace nsg::metrics {
namespace {

TileMeasurement measured(const Graph& gt, const Graph& pred) { return measure("t", gt, &pred, MetricParams{}); }

// A Y: 0 (50, 128) -> 1 (100, 128), which splits to 2 (150, 100) and 3 (150, 156).
// The stem is 50 px (24 interior samples), each branch √(50² + 28²) = 57.3 px (28).
Graph y_split() { return {{{50, 128}, {100, 128}, {150, 100}, {150, 156}}, {{0, 1}, {1, 2}, {1, 3}}, {}, {}, {}}; }

TEST(JunctionTopo, APerfectPredictionScoresOne) {
  const TileMeasurement t = measured(y_split(), y_split());
  EXPECT_EQ(t.counts[kJtopoSeeds], 1);  // node 1, the only split
  EXPECT_DOUBLE_EQ(*t.values[kJtopoPrecision], 1.0);
  EXPECT_DOUBLE_EQ(*t.values[kJtopoRecall], 1.0);
  EXPECT_DOUBLE_EQ(*t.values[kJtopoF1], 1.0);
}

TEST(JunctionTopo, AMissingBranchCostsRecallAtTheJunction) {
  // The prediction has the stem and the upper branch: 3 nodes + 24 + 28 = 55 samples, all
  // matched (M = 55) among the ground truth's 4 + 24 + 28 + 28 = 84. From the split, the
  // directed search reaches node 1 and both branches on the ground truth (1 + 2 × 29 = 59
  // samples), node 1 and one branch on the prediction (30), all 30 matched:
  // p_s = 30/30, r_s = 30/59. JTOPO P = (55/55) · 1, R = (55/84) · (30/59).
  const Graph pred{{{50, 128}, {100, 128}, {150, 100}}, {{0, 1}, {1, 2}}, {}, {}, {}};
  const TileMeasurement t = measured(y_split(), pred);
  EXPECT_EQ(t.counts[kGeoMatched], 55);
  EXPECT_EQ(t.counts[kJtopoSeeds], 1);
  EXPECT_DOUBLE_EQ(*t.values[kJtopoPrecision], 1.0);
  EXPECT_NEAR(*t.values[kJtopoRecall], 55.0 / 84.0 * (30.0 / 59.0), 1e-12);
  const double p = 1.0, r = 55.0 / 84.0 * (30.0 / 59.0);
  EXPECT_NEAR(*t.values[kJtopoF1], 2 * p * r / (p + r), 1e-12);
  // Plain TOPO averages over every seed, most of them far from the junction: higher.
  EXPECT_GT(*t.values[kTopoDirectedRecall], *t.values[kJtopoRecall]);
}

TEST(JunctionTopo, UndefinedWithoutAGroundTruthSplit) {
  const Graph lane{{{50, 128}, {150, 128}}, {{0, 1}}, {}, {}, {}};
  const TileMeasurement t = measured(lane, lane);
  EXPECT_EQ(t.counts[kJtopoSeeds], 0);
  EXPECT_FALSE(t.values[kJtopoPrecision]);
  EXPECT_FALSE(t.values[kJtopoRecall]);
  EXPECT_FALSE(t.values[kJtopoF1]);
}

TEST(JunctionTopo, AnUnmatchedJunctionScoresZero) {
  // A prediction far from the split: recall 0, precision 0 (it has samples), F1 0.
  const Graph far{{{50, 20}, {150, 20}}, {{0, 1}}, {}, {}, {}};
  const TileMeasurement t = measured(y_split(), far);
  EXPECT_EQ(t.counts[kJtopoSeeds], 0);
  EXPECT_EQ(*t.values[kJtopoPrecision], 0.0);
  EXPECT_EQ(*t.values[kJtopoRecall], 0.0);
  EXPECT_EQ(*t.values[kJtopoF1], 0.0);
  // An empty prediction: no precision to speak of, recall 0.
  const TileMeasurement none = measure("t", y_split(), nullptr, MetricParams{});
  EXPECT_FALSE(none.values[kJtopoPrecision]);
  EXPECT_EQ(*none.values[kJtopoRecall], 0.0);
}

// A lane 0 (50, 128) -> 1 (100, 128), 50 px (24 interior samples), then a connector inside
// an intersection 1 -> 2 (140, 128), 40 px (19). Node 1 belongs to both edges' classes.
Graph lane_then_connector() {
  Graph g{{{50, 128}, {100, 128}, {140, 128}}, {{0, 1}, {1, 2}}, {}, {}, {}};
  g.edge_flags = {0, kEdgeConnector | kEdgeInIntersection};
  return g;
}

TEST(ClassRecall, ALaneFoundAndAConnectorMissed) {
  // The prediction is the lane alone (26 samples, each matched to the one at its place):
  // lane class = nodes 0, 1 + 24 = 26 samples, all matched; connector class = nodes 1, 2 +
  // 19 = 21, only node 1 matched. TOPO: every seed reaches all 46 GT and 26 predicted
  // samples and matches 26, r_s = 26/46; the lane's 26 seeds sum to 26 · 26/46, the
  // connector's one (node 1) to 26/46.
  const Graph pred{{{50, 128}, {100, 128}}, {{0, 1}}, {}, {}, {}};
  const TileMeasurement t = measured(lane_then_connector(), pred);
  EXPECT_EQ(t.counts[kGeoGtSamplesLane], 26);
  EXPECT_EQ(t.counts[kGeoGtSamplesConnector], 21);
  EXPECT_EQ(t.counts[kGeoMatchedLane], 26);
  EXPECT_EQ(t.counts[kGeoMatchedConnector], 1);
  EXPECT_EQ(t.counts[kGeoGtSamplesInIntersection], 21);
  EXPECT_EQ(t.counts[kGeoGtSamplesOutsideIntersection], 26);
  EXPECT_DOUBLE_EQ(*t.values[kGeoRecallLane], 1.0);
  EXPECT_DOUBLE_EQ(*t.values[kGeoRecallConnector], 1.0 / 21.0);
  EXPECT_DOUBLE_EQ(*t.values[kGeoRecallInIntersection], 1.0 / 21.0);
  EXPECT_DOUBLE_EQ(*t.values[kGeoRecallOutsideIntersection], 1.0);
  EXPECT_NEAR(*t.values[kTopoRecallLane], 26.0 / 46.0, 1e-12);
  EXPECT_NEAR(*t.values[kTopoRecallConnector], 26.0 / 46.0 / 21.0, 1e-12);
  // The headline values do not depend on the flags.
  Graph unflagged = lane_then_connector();
  unflagged.edge_flags.clear();
  const TileMeasurement plain = measured(unflagged, pred);
  for (int m = 0; m < kJtopoPrecision; ++m) EXPECT_EQ(plain.values[m], t.values[m]) << metric_name(m);
}

TEST(ClassRecall, UndefinedWithoutFlagsOrWithoutTheClass) {
  Graph unflagged = lane_then_connector();
  unflagged.edge_flags.clear();
  const TileMeasurement none = measured(unflagged, unflagged);
  for (int m = kGeoRecallLane; m <= kTopoRecallOutsideIntersection; ++m) EXPECT_FALSE(none.values[m]) << metric_name(m);
  // Lanes only: the connector and intersection classes have no sample.
  Graph lanes{{{50, 128}, {150, 128}}, {{0, 1}}, {}, {}, {0}};
  const TileMeasurement t = measured(lanes, lanes);
  EXPECT_DOUBLE_EQ(*t.values[kGeoRecallLane], 1.0);
  EXPECT_FALSE(t.values[kGeoRecallConnector]);
  EXPECT_FALSE(t.values[kTopoRecallInIntersection]);
  EXPECT_DOUBLE_EQ(*t.values[kTopoRecallOutsideIntersection], 1.0);
}

TEST(ClassRecall, FlagsMustMatchTheEdges) {
  Graph bad = lane_then_connector();
  bad.edge_flags.pop_back();
  EXPECT_THROW(measured(bad, bad), DataError);
}

}  // namespace
}  // namespace nsg::metrics

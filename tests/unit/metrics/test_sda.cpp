// Split detection (SDA@20, SDA@50; docs/metrics.md "Metrics v2") on cases worked by hand:
// a split point is a node with two or more outgoing edges; the two graphs' split points are
// paired by the assignment of least total distance and a pair closer than R is a hit.
#include <gtest/gtest.h>

#include <vector>

#include "nsg/metrics/measure.h"

namespace nsg::metrics {
namespace {

// A fork at each point: the node, and two edges out of it to nodes 5 px away.
Graph forks(const std::vector<Point>& at) {
  Graph g;
  for (const Point& p : at) {
    const auto n = static_cast<int32_t>(g.nodes.size());
    g.nodes.push_back(p);
    g.nodes.push_back({p.u + 5.0, p.v - 3.0});
    g.nodes.push_back({p.u + 5.0, p.v + 3.0});
    g.edges.push_back({n, n + 1});
    g.edges.push_back({n, n + 2});
  }
  return g;
}

TileMeasurement measured(const Graph& gt, const Graph& pred) { return measure("t", gt, &pred, MetricParams{}); }

TEST(SplitDetection, AHitWithinTheRadiusAndAMissBeyondIt) {
  const TileMeasurement near = measured(forks({{100, 100}}), forks({{115, 100}}));  // 15 px
  EXPECT_EQ(near.values[kSda20Precision], 1.0);
  EXPECT_EQ(near.values[kSda20Recall], 1.0);
  EXPECT_EQ(near.values[kSda50Recall], 1.0);
  const TileMeasurement far = measured(forks({{100, 100}}), forks({{130, 100}}));  // 30 px
  EXPECT_EQ(far.values[kSda20Precision], 0.0);
  EXPECT_EQ(far.values[kSda20Recall], 0.0);
  EXPECT_EQ(far.values[kSda50Precision], 1.0);
  EXPECT_EQ(far.values[kSda50Recall], 1.0);
  EXPECT_EQ(far.counts[kSdaGtSplits], 1);
  EXPECT_EQ(far.counts[kSdaPredSplits], 1);
  EXPECT_EQ(far.counts[kSda20Matched], 0);
  EXPECT_EQ(far.counts[kSda50Matched], 1);
}

TEST(SplitDetection, PrecisionAndRecallCountTheirOwnSide) {
  // Three true splits, two predicted near two of them and one far from all.
  const TileMeasurement t = measured(forks({{50, 50}, {150, 50}, {50, 150}}), forks({{52, 50}, {150, 55}, {200, 200}}));
  EXPECT_EQ(t.counts[kSda20Matched], 2);
  EXPECT_DOUBLE_EQ(*t.values[kSda20Precision], 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(*t.values[kSda20Recall], 2.0 / 3.0);
  const TileMeasurement fewer = measured(forks({{50, 50}, {150, 50}, {50, 150}}), forks({{52, 50}}));
  EXPECT_DOUBLE_EQ(*fewer.values[kSda20Precision], 1.0);
  EXPECT_DOUBLE_EQ(*fewer.values[kSda20Recall], 1.0 / 3.0);
}

TEST(SplitDetection, PairsByTheLeastTotalDistanceNotGreedily) {
  // Greedy in ground-truth order would pair A(0) with P(9) and leave B(18) with Q(-12), 30 px
  // away: one hit at 20 px. The least total distance pairs A-Q (12) and B-P (9): two hits.
  const TileMeasurement t = measured(forks({{100, 100}, {118, 100}}), forks({{109, 100}, {88, 100}}));
  EXPECT_EQ(t.counts[kSda20Matched], 2);
  EXPECT_EQ(t.values[kSda20Recall], 1.0);
}

TEST(SplitDetection, UndefinedWithoutATrueSplitZeroWithoutAPredictedOne) {
  Graph line;
  line.nodes = {{10, 10}, {20, 10}, {30, 10}};
  line.edges = {{0, 1}, {1, 2}};
  const TileMeasurement none = measured(line, forks({{15, 10}}));
  EXPECT_FALSE(none.values[kSda20Precision]);
  EXPECT_FALSE(none.values[kSda50Recall]);
  EXPECT_EQ(none.counts[kSdaPredSplits], 1);
  // As UrbanLaneGraph's calc_sda: a prediction without splits scores 0, precision included.
  const TileMeasurement missed = measured(forks({{15, 10}}), line);
  EXPECT_EQ(missed.values[kSda20Precision], 0.0);
  EXPECT_EQ(missed.values[kSda20Recall], 0.0);
  // A merge (two edges in) is no split point.
  Graph merge;
  merge.nodes = {{0, 0}, {0, 10}, {10, 5}};
  merge.edges = {{0, 2}, {1, 2}};
  EXPECT_EQ(measured(merge, merge).counts[kSdaGtSplits], 0);
}

}  // namespace
}  // namespace nsg::metrics

// Analytic cases per metric family, where the answer is known by construction.
#include <gtest/gtest.h>

#include <cmath>

#include "nsg/core/error.h"
#include "nsg/metrics/measure.h"
#include "nsg/metrics/params.h"

namespace nsg::metrics {
namespace {

// A straight lane along v = row from u = 20 to 220, one node every 10 px, directed +u.
Graph lane(double row, double shift_u = 0.0, bool reversed = false) {
  Graph g;
  for (int k = 0; k <= 20; ++k) g.nodes.push_back({20.0 + 10.0 * k + shift_u, row});
  for (int64_t k = 0; k < 20; ++k)
    g.edges.push_back(reversed ? std::array<int64_t, 2>{k + 1, k} : std::array<int64_t, 2>{k, k + 1});
  return g;
}

Graph two_lanes() {  // a road: +u lane at row 120, -u lane at row 137.5 (3.5 m apart)
  Graph g = lane(120.0);
  const Graph back = lane(137.5, 0.0, true);
  const auto offset = static_cast<int64_t>(g.nodes.size());
  for (const Point& p : back.nodes) g.nodes.push_back(p);
  for (const auto& [i, j] : back.edges) g.edges.push_back({i + offset, j + offset});
  return g;
}

double value(const TileMeasurement& t, Metric m) {
  EXPECT_TRUE(t.values[m].has_value()) << metric_name(m);
  return t.values[m].value_or(-1.0);
}

const MetricParams kParams;

TEST(Analytic, IdenticalGraphsScorePerfect) {
  const Graph g = two_lanes();
  const TileMeasurement t = measure("k", g, &g, kParams);
  for (Metric m : {kApls, kAplsDirected, kAplsStrict, kDirectionAccuracy, kF1, kIou, kGeoF1, kTopoF1, kTopoDirectedF1,
                   kDirectionMatchedFraction})
    EXPECT_DOUBLE_EQ(value(t, m), 1.0) << metric_name(m);
  EXPECT_DOUBLE_EQ(value(t, kChamferPx2), 0.0);
  EXPECT_DOUBLE_EQ(value(t, kChamferMeanM), 0.0);
  // Two separate lanes of 21 nodes: only pairs within a lane have a path.
  EXPECT_EQ(t.counts[kAplsGtPairs], 2 * 21 * 20);
  EXPECT_EQ(t.counts[kGtPx], t.counts[kInterPx]);
  EXPECT_EQ(t.counts[kMissingPrediction], 0);
}

TEST(Analytic, ShiftByKnownVectorGivesKnownChamfer) {
  const Graph g = lane(128.0);
  const Graph p = lane(128.0, 3.0);  // every node 3 px along the lane (neighbours 7 px away)
  const TileMeasurement t = measure("k", g, &p, kParams);
  EXPECT_NEAR(value(t, kChamferPx2), 2.0 * 21 * 9.0, 1e-9);
  EXPECT_NEAR(value(t, kChamferM2), 2.0 * 21 * 9.0 * 0.04, 1e-9);
  EXPECT_NEAR(value(t, kChamferMeanM), 3.0 * 0.2, 1e-12);
  EXPECT_DOUBLE_EQ(value(t, kDirectionAccuracy), 1.0);
}

TEST(Analytic, LateralShiftBeyondStrictSnap) {
  const Graph g = lane(128.0);
  Graph p = g;
  for (Point& n : p.nodes) n.v += 10.0;  // 2 m: within the 4 m snap, beyond 1.8 m
  const TileMeasurement t = measure("k", g, &p, kParams);
  EXPECT_NEAR(value(t, kApls), 1.0, 1e-12);
  EXPECT_DOUBLE_EQ(value(t, kAplsStrict), 0.0);
  EXPECT_DOUBLE_EQ(value(t, kGeoF1), 0.0);  // 10 px > 8 px match radius
  EXPECT_NEAR(value(t, kChamferMeanM), 2.0, 1e-12);
  // Midpoints 10 px from GT > 9 px: no predicted edge is matched.
  EXPECT_FALSE(t.values[kDirectionAccuracy].has_value());
  EXPECT_DOUBLE_EQ(value(t, kDirectionMatchedFraction), 0.0);
}

TEST(Analytic, ReversedLaneIsWrongDirection) {
  const Graph g = lane(128.0);
  const Graph p = lane(128.0, 0.0, true);
  const TileMeasurement t = measure("k", g, &p, kParams);
  EXPECT_DOUBLE_EQ(value(t, kDirectionAccuracy), 0.0);
  EXPECT_DOUBLE_EQ(value(t, kDirectionAccuracyLengthWeighted), 0.0);
  EXPECT_DOUBLE_EQ(value(t, kApls), 1.0);  // undirected: same geometry
  EXPECT_LT(value(t, kAplsDirected), 0.5);
  EXPECT_DOUBLE_EQ(value(t, kTopoF1), 1.0);
  EXPECT_LT(value(t, kTopoDirectedF1), value(t, kTopoF1));
}

TEST(Analytic, MissingEdgeBreaksPaths) {
  const Graph g = lane(128.0);
  Graph p = g;
  p.edges.erase(p.edges.begin() + 10);  // cut the lane in the middle
  const TileMeasurement t = measure("k", g, &p, kParams);
  EXPECT_LT(value(t, kApls), 0.9);
  // GT pairs across the cut (11 * 10 * 2 ordered) have no predicted path: cost 1 each.
  EXPECT_NEAR(*t.values[kAplsGtToPred], 1.0 - 220.0 / 420.0, 1e-12);
  EXPECT_DOUBLE_EQ(value(t, kDirectionAccuracy), 1.0);
  EXPECT_LT(value(t, kF1), 1.0);
  EXPECT_LT(value(t, kTopoRecall), value(t, kGeoRecall));
}

TEST(Analytic, EmptyBoth) {
  const Graph e;
  const TileMeasurement t = measure("k", e, &e, kParams);
  for (int m = 0; m < kMetricCount; ++m) {
    if (m == kChamferPx2 || m == kChamferM2 || m == kChamferMeanM)
      EXPECT_DOUBLE_EQ(value(t, static_cast<Metric>(m)), 0.0);
    else EXPECT_FALSE(t.values[m].has_value()) << metric_name(m);
  }
}

TEST(Analytic, EmptyPredictionAndMissingTile) {
  const Graph g = lane(128.0);
  const TileMeasurement t = measure("k", g, nullptr, kParams);
  EXPECT_EQ(t.counts[kMissingPrediction], 1);
  EXPECT_DOUBLE_EQ(value(t, kApls), 0.0);
  EXPECT_DOUBLE_EQ(value(t, kF1), 0.0);
  EXPECT_DOUBLE_EQ(value(t, kIou), 0.0);
  EXPECT_DOUBLE_EQ(value(t, kGeoRecall), 0.0);
  EXPECT_DOUBLE_EQ(value(t, kTopoRecall), 0.0);
  EXPECT_FALSE(t.values[kGeoPrecision].has_value());
  EXPECT_FALSE(t.values[kChamferPx2].has_value());
  EXPECT_FALSE(t.values[kAplsPredToGt].has_value());
}

TEST(Analytic, EmptyGroundTruth) {
  const Graph e, p = lane(128.0);
  const TileMeasurement t = measure("k", e, &p, kParams);
  EXPECT_FALSE(t.values[kApls].has_value());
  EXPECT_DOUBLE_EQ(value(t, kGeoPrecision), 0.0);
  EXPECT_FALSE(t.values[kGeoRecall].has_value());
  EXPECT_DOUBLE_EQ(value(t, kF1), 0.0);
}

TEST(Analytic, SelfLoopsAndDuplicatesAreDroppedAndCounted) {
  const Graph g = lane(128.0);
  Graph p = g;
  p.edges.push_back({3, 3});
  p.edges.push_back({4, 5});
  p.edges.push_back({4, 5});
  const TileMeasurement t = measure("k", g, &p, kParams);
  EXPECT_EQ(t.counts[kPredSelfLoopsDropped], 1);
  EXPECT_EQ(t.counts[kPredDuplicateEdgesDropped], 2);
  EXPECT_DOUBLE_EQ(value(t, kApls), 1.0);
  EXPECT_EQ(t.counts[kDirectionPredEdges], 20);
}

TEST(Analytic, CapsuleMaskIsExactlyNinePixelsWide) {
  Graph g;
  g.nodes = {{50.0, 100.0}, {150.0, 100.0}};
  g.edges = {{0, 1}};
  const TileMeasurement t = measure("k", g, &g, kParams);
  // Straight part: 101 columns x 9 rows; each round cap of radius 4.5 adds the pixel
  // centres with 0 < du <= 4.5 and du^2 + dv^2 <= 20.25.
  int64_t cap = 0;
  for (int du = 1; du <= 4; ++du)
    for (int dv = -4; dv <= 4; ++dv)
      if (du * du + dv * dv <= 20.25) ++cap;
  EXPECT_EQ(t.counts[kGtPx], 101 * 9 + 2 * cap);
}

TEST(Aggregate, UndefinedValuesAreCountedNotZero) {
  const Graph g = lane(128.0), e;
  Aggregate agg;
  agg.add(measure("a", g, &g, kParams));
  agg.add(measure("b", e, &e, kParams));
  const AggregateReport r = finalize(agg);
  EXPECT_EQ(r.n_tiles, 2);
  EXPECT_DOUBLE_EQ(r.mean[kApls].value(), 1.0);
  EXPECT_EQ(r.n_defined[kApls], 1);
  EXPECT_EQ(r.n_undefined[kApls], 1);
  EXPECT_DOUBLE_EQ(r.pooled_f1.value(), 1.0);

  Aggregate left, right;  // merging shards equals adding in order
  left.add(measure("a", g, &g, kParams));
  right.add(measure("b", e, &e, kParams));
  left.merge(right);
  EXPECT_EQ(left.value_sums, agg.value_sums);
  EXPECT_EQ(left.count_sums, agg.count_sums);
}

TEST(Params, ValidateAndJsonRoundTrip) {
  MetricParams p;
  p.snap_m = 3.0;
  const MetricParams q = MetricParams::from_json(p.to_json());
  EXPECT_EQ(q.to_json(), p.to_json());
  MetricParams bad;
  bad.geo_match_px = -1.0;
  EXPECT_THROW(bad.validate(), ConfigError);
  EXPECT_THROW(MetricParams::from_json({{"snap_meters", 4.0}}), ConfigError);
  EXPECT_THROW(MetricParams::from_json({{"snap_m", "4"}}), ConfigError);
}

}  // namespace
}  // namespace nsg::metrics

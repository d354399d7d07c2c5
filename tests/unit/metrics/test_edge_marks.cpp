// Per-edge marks of the direction test on graphs drawn by hand, and their agreement with
// the tile's direction counts on a mixed case.
#include <gtest/gtest.h>

#include "nsg/metrics/edge_marks.h"
#include "nsg/metrics/measure.h"

namespace nsg::metrics {
namespace {

// A straight GT lane along v = 50 from u = 10 to u = 110 (two edges, eastbound).
Graph east_lane() { return {{{10, 50}, {60, 50}, {110, 50}}, {{0, 1}, {1, 2}}, {}, {}, {}}; }

TEST(EdgeMarks, CorrectWrongUnmatchedAndMissed) {
  Graph pred;
  pred.nodes = {{10, 52},  {60, 52},   // 0->1: 2 px off, same direction: correct
                {110, 48}, {60, 48},   // 2->3: 2 px off, westbound: wrong direction
                {10, 150}, {60, 150},  // 4->5: 100 px away: unmatched
                {5, 5}};               // 6->6: self-loop, dropped by cleaning
  pred.edges = {{0, 1}, {2, 3}, {4, 5}, {6, 6}};
  const MetricParams params;
  const EdgeMarks m = mark_edges(east_lane(), &pred, params);
  ASSERT_EQ(m.pred.edges.size(), 3u);  // the self-loop is gone, as in scoring
  EXPECT_EQ(m.pred_marks, (std::vector<PredEdgeMark>{PredEdgeMark::kCorrect, PredEdgeMark::kWrongDirection,
                                                     PredEdgeMark::kUnmatched}));
  EXPECT_EQ(m.gt_missed, (std::vector<bool>{false, false}));  // both GT edges have a prediction nearby

  // The marks add up to the tile's direction counts.
  const TileMeasurement t = measure("k", east_lane(), &pred, params);
  EXPECT_EQ(t.counts[kDirectionMatched], 2);
  EXPECT_EQ(t.counts[kDirectionCorrect], 1);
}

TEST(EdgeMarks, MissingPredictionMissesEveryGtEdge) {
  const EdgeMarks m = mark_edges(east_lane(), nullptr, MetricParams{});
  EXPECT_TRUE(m.pred_marks.empty());
  EXPECT_EQ(m.gt_missed, (std::vector<bool>{true, true}));
  // Only the eastern half predicted: the western GT edge is missed.
  Graph half{{{60, 50}, {110, 50}}, {{0, 1}}, {}, {}, {}};
  EXPECT_EQ(mark_edges(east_lane(), &half, MetricParams{}).gt_missed, (std::vector<bool>{true, false}));
}

TEST(EdgeMarks, BothWaysLaneAcceptsEitherDirection) {
  Graph gt{{{10, 50}, {110, 50}}, {{0, 1}, {1, 0}}, {}, {}, {}};
  Graph pred{{{100, 51}, {20, 51}}, {{0, 1}}, {}, {}, {}};
  EXPECT_EQ(mark_edges(gt, &pred, MetricParams{}).pred_marks, std::vector<PredEdgeMark>{PredEdgeMark::kCorrect});
}

}  // namespace
}  // namespace nsg::metrics

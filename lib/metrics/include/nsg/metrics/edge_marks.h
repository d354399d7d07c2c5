#pragma once
// Which edges of one tile the direction test matched, for drawing (the report's tile view):
// every predicted edge is correct, matched with the wrong direction, or unmatched, by the
// rule of `direction_accuracy` (docs/metrics.md "Direction accuracy"), so the marks add up to
// the tile's direction counts. GT edges no predicted edge comes near (the same rule seen
// from the GT side) are marked missed. Not a metric: a picture of where the errors are.
#include <cstdint>
#include <vector>

#include "nsg/metrics/graph.h"
#include "nsg/metrics/params.h"

namespace nsg::metrics {

enum class PredEdgeMark : uint8_t {
  kCorrect = 0,         // matched, direction agrees with a nearest GT segment
  kWrongDirection = 1,  // matched, no nearest GT segment agrees
  kUnmatched = 2,       // midpoint farther than direction_match_px from every GT segment
  kZeroLength = 3,      // not scored by the direction test
};

struct EdgeMarks {
  CleanGraph gt, pred;                   // the graphs the marks index (self-loops, duplicates dropped)
  std::vector<PredEdgeMark> pred_marks;  // one per pred.edges
  std::vector<bool> gt_missed;           // one per gt.edges: no predicted segment within
                                         // direction_match_px of its midpoint
};

// `pred` == nullptr: the tile is missing from the submission (every GT edge is missed).
EdgeMarks mark_edges(const Graph& gt, const Graph* pred, const MetricParams& params);

}  // namespace nsg::metrics

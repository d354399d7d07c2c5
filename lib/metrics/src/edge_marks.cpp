// Per-edge marks of the direction test (edge_marks.h). The scan is the one of
// compute_direction without its grid: a tile has a few hundred edges and this runs only
// for drawing, so the plain all-pairs loop keeps the rule readable.
#include "nsg/metrics/edge_marks.h"

#include <cmath>
#include <limits>

#include "internal.h"

namespace nsg::metrics {
namespace {

constexpr double kDirectionTiePx = 1e-9;  // as in compute_direction

struct Seg {
  double ax, ay, bx, by;
};

// Non-zero-length segments of `g`, with the index of the edge each came from.
std::vector<Seg> segments(const CleanGraph& g, std::vector<size_t>* edge_of = nullptr) {
  std::vector<Seg> out;
  for (size_t e = 0; e < g.edges.size(); ++e) {
    const Point a = g.nodes[g.edges[e][0]], b = g.nodes[g.edges[e][1]];
    if (a.u == b.u && a.v == b.v) continue;
    out.push_back({a.u, a.v, b.u, b.v});
    if (edge_of) edge_of->push_back(e);
  }
  return out;
}

double distance(double px, double py, const Seg& s) {
  return std::sqrt(detail::point_segment(px, py, s.ax, s.ay, s.bx, s.by).d2);
}

}  // namespace

EdgeMarks mark_edges(const Graph& gt, const Graph* pred, const MetricParams& params) {
  EdgeMarks marks;
  marks.gt = clean_graph(gt);
  if (pred) marks.pred = clean_graph(*pred);
  const std::vector<Seg> gt_segs = segments(marks.gt);
  const std::vector<Seg> pred_segs = segments(marks.pred);

  marks.pred_marks.assign(marks.pred.edges.size(), PredEdgeMark::kUnmatched);
  std::vector<double> dist(gt_segs.size());
  for (size_t e = 0; e < marks.pred.edges.size(); ++e) {
    const Point a = marks.pred.nodes[marks.pred.edges[e][0]], b = marks.pred.nodes[marks.pred.edges[e][1]];
    const double dx = b.u - a.u, dy = b.v - a.v;
    if (dx == 0.0 && dy == 0.0) {
      marks.pred_marks[e] = PredEdgeMark::kZeroLength;
      continue;
    }
    const double mx = (a.u + b.u) / 2.0, my = (a.v + b.v) / 2.0;
    double dmin = std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < gt_segs.size(); ++k) dmin = std::min(dmin, dist[k] = distance(mx, my, gt_segs[k]));
    if (!(dmin <= params.direction_match_px)) continue;
    marks.pred_marks[e] = PredEdgeMark::kWrongDirection;
    for (size_t k = 0; k < gt_segs.size(); ++k) {
      if (dist[k] > dmin + kDirectionTiePx) continue;
      const Seg& s = gt_segs[k];
      if (dx * (s.bx - s.ax) + dy * (s.by - s.ay) > 0.0) {
        marks.pred_marks[e] = PredEdgeMark::kCorrect;
        break;
      }
    }
  }

  marks.gt_missed.assign(marks.gt.edges.size(), true);
  for (size_t e = 0; e < marks.gt.edges.size(); ++e) {
    const Point a = marks.gt.nodes[marks.gt.edges[e][0]], b = marks.gt.nodes[marks.gt.edges[e][1]];
    const double mx = (a.u + b.u) / 2.0, my = (a.v + b.v) / 2.0;
    for (const Seg& s : pred_segs)
      if (distance(mx, my, s) <= params.direction_match_px) {
        marks.gt_missed[e] = false;
        break;
      }
  }
  return marks;
}

}  // namespace nsg::metrics

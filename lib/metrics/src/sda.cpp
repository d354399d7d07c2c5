// Split detection (UrbanLaneGraph's SDA@R, docs/metrics.md "Metrics v2"): the split points
// of each graph (nodes with two or more outgoing edges) paired one to one by the assignment
// of least total distance, a pair within R px a hit. Reimplemented from the definition;
// tests/python holds it to UrbanLaneGraph's calc_sda on worked cases.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "internal.h"

namespace nsg::metrics::detail {
namespace {

std::vector<Point> split_points(const CleanGraph& g) {
  std::vector<int32_t> out_degree(g.nodes.size(), 0);
  for (const auto& e : g.edges) ++out_degree[static_cast<size_t>(e[0])];
  std::vector<Point> out;
  for (size_t k = 0; k < g.nodes.size(); ++k)
    if (out_degree[k] >= 2) out.push_back(g.nodes[k]);
  return out;
}

// The least-cost assignment of every row to a distinct column (rows ≤ columns) of
// cost(r, c): the shortest augmenting path method with potentials (Jonker–Volgenant's
// form of the Hungarian algorithm), O(rows² · columns). Returns each row's column.
template <typename Cost>
std::vector<int32_t> assign_rows(int32_t rows, int32_t cols, const Cost& cost) {
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> u(static_cast<size_t>(rows) + 1, 0.0), v(static_cast<size_t>(cols) + 1, 0.0);
  std::vector<int32_t> row_of(static_cast<size_t>(cols) + 1, 0), way(static_cast<size_t>(cols) + 1, 0);
  for (int32_t r = 1; r <= rows; ++r) {
    row_of[0] = r;
    int32_t c0 = 0;
    std::vector<double> min_to(static_cast<size_t>(cols) + 1, inf);
    std::vector<char> used(static_cast<size_t>(cols) + 1, 0);
    do {
      used[c0] = 1;
      const int32_t r0 = row_of[c0];
      double delta = inf;
      int32_t c1 = 0;
      for (int32_t c = 1; c <= cols; ++c) {
        if (used[c]) continue;
        const double reduced = cost(r0 - 1, c - 1) - u[r0] - v[c];
        if (reduced < min_to[c]) {
          min_to[c] = reduced;
          way[c] = c0;
        }
        if (min_to[c] < delta) {
          delta = min_to[c];
          c1 = c;
        }
      }
      for (int32_t c = 0; c <= cols; ++c) {
        if (used[c]) {
          u[row_of[c]] += delta;
          v[c] -= delta;
        } else {
          min_to[c] -= delta;
        }
      }
      c0 = c1;
    } while (row_of[c0] != 0);
    do {  // flip the augmenting path
      const int32_t c1 = way[c0];
      row_of[c0] = row_of[c1];
      c0 = c1;
    } while (c0 != 0);
  }
  std::vector<int32_t> column(static_cast<size_t>(rows), -1);
  for (int32_t c = 1; c <= cols; ++c)
    if (row_of[c] != 0) column[static_cast<size_t>(row_of[c] - 1)] = c - 1;
  return column;
}

}  // namespace

SdaResult compute_sda(const CleanGraph& gt, const CleanGraph& pred, const std::vector<double>& radii_px,
                      WorkMeter& meter) {
  SdaResult r;
  const std::vector<Point> g = split_points(gt), p = split_points(pred);
  r.gt_splits = static_cast<int64_t>(g.size());
  r.pred_splits = static_cast<int64_t>(p.size());
  r.matched.assign(radii_px.size(), 0);
  std::vector<double> pair_px;  // the assigned pairs' distances
  if (!g.empty() && !p.empty()) {
    // Rows are the smaller side, as scipy's linear_sum_assignment transposes a tall matrix.
    const bool gt_rows = g.size() <= p.size();
    const std::vector<Point>& rows = gt_rows ? g : p;
    const std::vector<Point>& cols = gt_rows ? p : g;
    meter.spend(static_cast<int64_t>(rows.size()) * static_cast<int64_t>(rows.size()) *
                static_cast<int64_t>(cols.size()));
    const auto distance = [&](int32_t a, int32_t b) {
      return std::hypot(rows[static_cast<size_t>(a)].u - cols[static_cast<size_t>(b)].u,
                        rows[static_cast<size_t>(a)].v - cols[static_cast<size_t>(b)].v);
    };
    const std::vector<int32_t> column =
        assign_rows(static_cast<int32_t>(rows.size()), static_cast<int32_t>(cols.size()), distance);
    for (size_t a = 0; a < column.size(); ++a) pair_px.push_back(distance(static_cast<int32_t>(a), column[a]));
  }
  for (size_t k = 0; k < radii_px.size(); ++k)
    r.matched[k] = std::count_if(pair_px.begin(), pair_px.end(), [&](double d) { return d < radii_px[k]; });
  return r;
}

}  // namespace nsg::metrics::detail

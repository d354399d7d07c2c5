#pragma once
// The metric families, each a plain function of two cleaned graphs (docs/metrics.md).
#include <array>
#include <cstdint>
#include <optional>

#include "nsg/metrics/graph.h"
#include "nsg/metrics/params.h"

namespace nsg::metrics::detail {

// Squared distance from p to segment ab (t clamped to [0, 1]); also returns t.
struct SegmentDistance {
  double d2 = 0.0;
  double t = 0.0;
};
SegmentDistance point_segment(double px, double py, double ax, double ay, double bx, double by);

struct AplsResult {
  std::optional<double> apls, gt_to_pred, pred_to_gt;
  int64_t gt_pairs = 0, pred_pairs = 0;
};
struct AplsFamily {
  AplsResult undirected, directed, strict;
};
// The searches whose cost grows faster than the input — APLS's shortest paths on both
// graphs, TOPO's radius searches and their matching updates — spend units in proportion
// to their time: two per settled node and per arc of a shortest-path search (heap
// operations), one per sorted node, TOPO chain step, changed sample or re-decided match. The meter stops the tile
// (OverBudget) once they spend more than the limit, so a tile's scoring time is bounded whatever the two graphs are
// (docs/scoring-limits.md). The count is the same on every machine.
struct OverBudget {};
class WorkMeter {
 public:
  explicit WorkMeter(int64_t limit) : limit_(limit) {}
  void spend(int64_t units) {
    used_ += units;
    if (used_ > limit_) throw OverBudget{};
  }
  int64_t used() const { return used_; }
  int64_t limit() const { return limit_; }

 private:
  int64_t limit_;
  int64_t used_ = 0;
};

AplsFamily compute_apls(const CleanGraph& gt, const CleanGraph& pred, const MetricParams& params, WorkMeter& meter);

struct DirectionResult {
  std::optional<double> accuracy, accuracy_length_weighted, matched_fraction;
  int64_t pred_edges = 0, matched = 0, correct = 0;
};
DirectionResult compute_direction(const CleanGraph& gt, const CleanGraph& pred, const MetricParams& params);

// Split detection (sda.cpp): the split points of each graph and, per radius, the pairs of
// the least-cost assignment closer than it.
struct SdaResult {
  int64_t gt_splits = 0, pred_splits = 0;
  std::vector<int64_t> matched;  // per radius
};
SdaResult compute_sda(const CleanGraph& gt, const CleanGraph& pred, const std::vector<double>& radii_px,
                      WorkMeter& meter);

struct MaskResult {
  int64_t gt_px = 0, pred_px = 0, inter_px = 0, union_px = 0;
};
MaskResult compute_masks(const CleanGraph& gt, const CleanGraph& pred, const MetricParams& params);

struct ChamferResult {
  std::optional<double> px2, m2, mean_m;
};
ChamferResult compute_chamfer(const CleanGraph& gt, const CleanGraph& pred, const MetricParams& params);

struct GeoTopoResult {
  std::optional<double> geo_precision, geo_recall, geo_f1;
  std::optional<double> topo_precision, topo_recall, topo_f1;
  std::optional<double> topo_directed_precision, topo_directed_recall, topo_directed_f1;
  int64_t gt_samples = 0, pred_samples = 0, matched = 0, seeds = 0;
  // Metrics v2: junction TOPO (directed, seeded at ground-truth split nodes) and, when the
  // ground truth has edge flags, GEO and TOPO recall per EdgeClass.
  std::optional<double> jtopo_precision, jtopo_recall, jtopo_f1;
  int64_t jtopo_seeds = 0;
  std::array<std::optional<double>, kEdgeClassCount> geo_recall_by_class{}, topo_recall_by_class{};
  std::array<int64_t, kEdgeClassCount> gt_samples_by_class{}, matched_by_class{};
};
GeoTopoResult compute_geo_topo(const CleanGraph& gt, const CleanGraph& pred, const MetricParams& params,
                               WorkMeter& meter);

// A map-update tile's change metrics (change.cpp, docs/metrics.md "Map change"): counts of
// GEO samples of the current map, its prior and the prediction, from which measure() makes
// the values. Costs one unit of `meter` per pair of samples compared.
struct ChangeResult {
  struct Kind {
    int64_t samples = 0, detected = 0;
  };
  Kind all, added, removed, moved;  // change samples, by the kind their edges are labelled
  int64_t claims = 0, true_claims = 0;
  int64_t prior_kept = 0, false_changes = 0;
  int64_t unchanged_pred = 0, unchanged_pred_on_map = 0;
  int64_t unchanged_gt = 0, unchanged_gt_found = 0;
};
ChangeResult compute_changes(const CleanGraph& current, const CleanGraph& prior, const CleanGraph& pred,
                             const MetricParams& params, WorkMeter& meter);

// Ratio helpers shared by the families.
std::optional<double> ratio(double num, double den);  // undefined if den == 0
// F1 from precision/recall as TOPO defines it (rule 7).
std::optional<double> f1_of(std::optional<double> p, std::optional<double> r);

}  // namespace nsg::metrics::detail

#pragma once
// The metric families, each a plain function of two cleaned graphs (docs/metrics.md).
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
AplsFamily compute_apls(const CleanGraph& gt, const CleanGraph& pred, const MetricParams& params);

struct DirectionResult {
  std::optional<double> accuracy, accuracy_length_weighted, matched_fraction;
  int64_t pred_edges = 0, matched = 0, correct = 0;
};
DirectionResult compute_direction(const CleanGraph& gt, const CleanGraph& pred, const MetricParams& params);

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
};
GeoTopoResult compute_geo_topo(const CleanGraph& gt, const CleanGraph& pred, const MetricParams& params);

// Ratio helpers shared by the families.
std::optional<double> ratio(double num, double den);  // undefined if den == 0
// F1 from precision/recall as TOPO defines it (rule 7).
std::optional<double> f1_of(std::optional<double> p, std::optional<double> r);

}  // namespace nsg::metrics::detail

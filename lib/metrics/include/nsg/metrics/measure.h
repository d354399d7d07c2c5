#pragma once
// Per-tile measurements (values + the integer counts that explain them), a mergeable
// aggregate (sums and defined/undefined counts) and its finalization (docs/metrics.md
// "Aggregation over a split"). Undefined values are std::nullopt, never 0.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "nsg/core/error.h"
#include "nsg/metrics/graph.h"
#include "nsg/metrics/params.h"

namespace nsg::metrics {

// Per-tile metrics, in report order. Names: metric_name().
enum Metric : int {
  kApls,
  kAplsGtToPred,
  kAplsPredToGt,
  kAplsDirected,
  kAplsDirectedGtToPred,
  kAplsDirectedPredToGt,
  kAplsStrict,
  kAplsStrictGtToPred,
  kAplsStrictPredToGt,
  kDirectionAccuracy,
  kDirectionAccuracyLengthWeighted,
  kDirectionMatchedFraction,
  kF1,
  kIou,
  kChamferPx2,
  kChamferM2,
  kChamferMeanM,
  kGeoPrecision,
  kGeoRecall,
  kGeoF1,
  kTopoPrecision,
  kTopoRecall,
  kTopoF1,
  kTopoDirectedPrecision,
  kTopoDirectedRecall,
  kTopoDirectedF1,
  // Metrics v2 (docs/metrics.md): split detection at 20 and 50 px.
  kSda20Precision,
  kSda20Recall,
  kSda50Precision,
  kSda50Recall,
  // Junction TOPO (CGNet's JTOPO): directed TOPO seeded at ground-truth split nodes.
  kJtopoPrecision,
  kJtopoRecall,
  kJtopoF1,
  // GEO and TOPO recall per ground-truth edge class, in EdgeClass order (graph.h).
  kGeoRecallLane,
  kGeoRecallConnector,
  kGeoRecallInIntersection,
  kGeoRecallOutsideIntersection,
  kGeoRecallChanged,
  kGeoRecallUnchanged,
  kTopoRecallLane,
  kTopoRecallConnector,
  kTopoRecallInIntersection,
  kTopoRecallOutsideIntersection,
  kTopoRecallChanged,
  kTopoRecallUnchanged,
  // Metrics v4, on a map-update tile (its ground truth has a prior graph): change detection.
  kChangeRecall,
  kChangeRecallAdded,
  kChangeRecallRemoved,
  kChangeRecallMoved,
  kChangePrecision,
  kChangeF1,
  kFalseChangeRate,
  kUnchangedPrecision,
  kUnchangedRecall,
  kMetricCount
};
// Per-tile integer counts. Names: count_name().
enum Count : int {
  kMissingPrediction,
  kGtSelfLoopsDropped,
  kGtDuplicateEdgesDropped,
  kPredSelfLoopsDropped,
  kPredDuplicateEdgesDropped,
  kGtPx,
  kPredPx,
  kInterPx,
  kUnionPx,
  kGeoGtSamples,
  kGeoPredSamples,
  kGeoMatched,
  kTopoSeeds,
  kAplsGtPairs,
  kAplsPredPairs,
  kDirectionPredEdges,
  kDirectionMatched,
  kDirectionCorrect,
  kSdaGtSplits,
  kSdaPredSplits,
  kSda20Matched,
  kSda50Matched,
  kJtopoSeeds,
  kGeoGtSamplesLane,  // per EdgeClass, in its order
  kGeoGtSamplesConnector,
  kGeoGtSamplesInIntersection,
  kGeoGtSamplesOutsideIntersection,
  kGeoGtSamplesChanged,
  kGeoGtSamplesUnchanged,
  kGeoMatchedLane,  // per EdgeClass, in its order
  kGeoMatchedConnector,
  kGeoMatchedInIntersection,
  kGeoMatchedOutsideIntersection,
  kGeoMatchedChanged,
  kGeoMatchedUnchanged,
  // Map change (metrics v4): the change samples and those detected, in all and per kind.
  kChangeSamples,
  kChangeDetected,
  kChangeSamplesAdded,
  kChangeDetectedAdded,
  kChangeSamplesRemoved,
  kChangeDetectedRemoved,
  kChangeSamplesMoved,
  kChangeDetectedMoved,
  kChangeClaims,
  kChangeClaimsTrue,
  kPriorKeptSamples,
  kFalseChanges,
  kUnchangedPredSamples,
  kUnchangedPredOnMap,
  kUnchangedGtSamples,
  kUnchangedGtFound,
  kCountCount
};
// What a metric is, declared once (measure.cpp's table): its name in reports, its unit,
// which way is better, whether a leaderboard shows it by default and a line saying what it
// measures.
struct MetricInfo {
  const char* name;         // "apls", the score report's key
  const char* unit;         // "" for a fraction in [0, 1], else "px²", "m²", "m"
  bool lower_is_better;     // the Chamfer distances; every other metric: higher is better
  bool leaderboard;         // a default column of a leaderboard: a summary, not a one-way half or a variant
  const char* description;  // one line (docs/metrics.md has the definition)
};
const MetricInfo& metric_info(int metric);
const char* metric_name(int metric);
// The table of metric_info as `nsgraph score --list-metrics` prints it: "md" (the "Metric
// list" section of docs/metrics.md, which `make regen` rewrites) or "json".
std::string metric_list(const std::string& format);
const char* count_name(int count);

// The headline metrics as a leaderboard names them, in display order, declared once for
// `score --format md`, the report's summary and the leaderboard page. The summed Chamfer
// (m², it grows with a tile's nodes) is no headline; its mean per matched node is.
struct HeadlineMetric {
  int metric;         // a Metric (metric_info: name, direction)
  const char* label;  // "APLS dir."
  int digits;         // decimals shown
};
const std::vector<HeadlineMetric>& headline_metrics();

using MetricValues = std::array<std::optional<double>, kMetricCount>;
using Counts = std::array<int64_t, kCountCount>;

struct TileMeasurement {
  std::string key;
  MetricValues values{};
  Counts counts{};
  // The units of the search work limit the tile spent (not in the report: it describes the
  // scorer's cost, not the prediction; `score -v` logs it).
  int64_t search_work = 0;
};

// A tile whose APLS and TOPO searches on the two graphs together pass
// validate::SubmissionLimits::max_search_work_per_tile: the submission is beyond the
// scoring limits for this ground truth (exit 1, like a file beyond the per-tile limits).
// record(): the tile's JSON Pointer in the submission, "prediction:/tiles/<key>".
class SearchWorkExceeded : public Error {
 public:
  using Error::Error;
  int exit_code() const override { return kExitProblems; }
};

// Scores one tile. `pred` == nullptr means the tile is missing from the submission: it is
// scored as an empty prediction and counted (missing_prediction = 1). Throws DataError
// naming the key when either graph exceeds the scoring limits (validate::SubmissionLimits),
// SearchWorkExceeded when the two together cost more than the search work limit.
TileMeasurement measure(const std::string& key, const Graph& gt, const Graph* pred, const MetricParams& params);

// Mergeable sums over tiles. Merge tiles (and shards) in key order for bit-identical
// output regardless of threads.
struct Aggregate {
  int64_t n_tiles = 0;
  int64_t n_missing_predictions = 0;
  int64_t n_extra_predictions = 0;
  std::array<double, kMetricCount> value_sums{};
  std::array<int64_t, kMetricCount> n_defined{};
  std::array<int64_t, kMetricCount> n_undefined{};
  Counts count_sums{};

  void add(const TileMeasurement& tile);
  void merge(const Aggregate& other);
};

struct AggregateReport {
  int64_t n_tiles = 0;
  int64_t n_missing_predictions = 0;
  int64_t n_extra_predictions = 0;
  MetricValues mean{};  // macro mean over tiles where defined
  std::array<int64_t, kMetricCount> n_defined{};
  std::array<int64_t, kMetricCount> n_undefined{};
  std::optional<double> pooled_f1, pooled_iou, pooled_geo_precision, pooled_geo_recall, pooled_geo_f1;
  // Map change (metrics v4), from the summed counts: a tile holds few change samples, so
  // these weigh every change sample once where the means weigh every tile once.
  std::optional<double> pooled_change_recall, pooled_change_precision, pooled_false_change_rate;
  Counts sums{};
};
AggregateReport finalize(const Aggregate& aggregate);
// The pooled values by their report names ("f1", "iou", "geo_precision", …), in report order:
// the score report's and the HTML report's "pooled" read them from here.
std::vector<std::pair<const char*, std::optional<double>>> pooled_values(const AggregateReport& aggregate);

}  // namespace nsg::metrics

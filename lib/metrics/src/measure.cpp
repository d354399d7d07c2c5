#include "nsg/metrics/measure.h"

#include <cmath>
#include <utility>

#include <nlohmann/json.hpp>

#include "internal.h"
#include "nsg/core/error.h"
#include "nsg/core/strings.h"
#include "nsg/metrics/submission_input.h"
#include "nsg/validate/submission.h"

namespace nsg::metrics {
namespace {
// Every metric's facts, in Metric order (docs/metrics.md defines each): the score report, the
// markdown table, the report's sort arrows, the previews' worst-first order and the
// score-report schema's metric lists (a test keeps it equal) read them from here.
constexpr MetricInfo kMetrics[kMetricCount] = {
    {"apls", "", false, true, "APLS: path lengths between node pairs compared both ways, undirected (snap 4 m)"},
    {"apls_gt_to_pred", "", false, false, "APLS with the pairs sampled on the ground truth"},
    {"apls_pred_to_gt", "", false, false, "APLS with the pairs sampled on the prediction"},
    {"apls_directed", "", false, true, "APLS where a path must follow the edges' directions"},
    {"apls_directed_gt_to_pred", "", false, false, "directed APLS, pairs sampled on the ground truth"},
    {"apls_directed_pred_to_gt", "", false, false, "directed APLS, pairs sampled on the prediction"},
    {"apls_strict", "", false, true, "APLS with the 1.8 m snap radius: no snapping onto the neighbouring lane"},
    {"apls_strict_gt_to_pred", "", false, false, "strict APLS, pairs sampled on the ground truth"},
    {"apls_strict_pred_to_gt", "", false, false, "strict APLS, pairs sampled on the prediction"},
    {"direction_accuracy", "", false, true, "matched predicted edges pointing the ground truth's way / matched edges"},
    {"direction_accuracy_length_weighted", "", false, false, "direction accuracy weighted by edge length"},
    {"direction_matched_fraction", "", false, false, "predicted edges of non-zero length matched to the ground truth"},
    {"f1", "", false, true, "F1 (Dice) of the two graphs drawn as 1.8 m wide lane masks"},
    {"iou", "", false, true, "intersection over union of the two lane masks"},
    {"chamfer_px2", "px²", true, false,
     "squared distance of every node to the other graph's nearest node, summed both ways"},
    {"chamfer_m2", "m²", true, false, "chamfer_px2 in square metres"},
    {"chamfer_mean_m", "m", true, true,
     "mean distance of a node to the other graph's nearest node, both ways averaged"},
    {"geo_precision", "", false, true,
     "GEO precision: predicted samples matched one-to-one to ground-truth samples within 8 px"},
    {"geo_recall", "", false, true, "GEO recall: ground-truth samples matched one-to-one within 8 px"},
    {"geo_f1", "", false, true, "GEO F1"},
    {"topo_precision", "", false, true,
     "TOPO precision: matching precision of the sub-graphs within 40 m of each seed, averaged over the samples"},
    {"topo_recall", "", false, true,
     "TOPO recall: matching recall of the sub-graphs within 40 m of each seed, averaged over the samples"},
    {"topo_f1", "", false, true, "TOPO F1"},
    {"topo_directed_precision", "", false, false, "TOPO precision with the sub-graphs grown along edge directions"},
    {"topo_directed_recall", "", false, false, "TOPO recall with the sub-graphs grown along edge directions"},
    {"topo_directed_f1", "", false, false, "directed TOPO F1"},
    {"sda20_precision", "", false, false,
     "split detection (UrbanLaneGraph's SDA@20): predicted split points paired within 20 px / predicted ones"},
    {"sda20_recall", "", false, false, "split detection at 20 px: ground-truth split points paired / all of them"},
    {"sda50_precision", "", false, false, "split detection at 50 px (SDA@50): precision"},
    {"sda50_recall", "", false, false, "split detection at 50 px: recall"},
    {"jtopo_precision", "", false, false,
     "junction TOPO (CGNet's JTOPO): directed TOPO precision at the seeds on ground-truth split nodes"},
    {"jtopo_recall", "", false, false, "junction TOPO recall: directed TOPO recall at ground-truth split nodes"},
    {"jtopo_f1", "", false, false, "junction TOPO F1"},
    {"geo_recall_lane", "", false, false, "GEO recall on the ground truth's lane edges (not connectors)"},
    {"geo_recall_connector", "", false, false, "GEO recall on the ground truth's connector edges"},
    {"geo_recall_in_intersection", "", false, false, "GEO recall on ground-truth edges inside intersections"},
    {"geo_recall_outside_intersection", "", false, false, "GEO recall on ground-truth edges outside intersections"},
    {"geo_recall_changed", "", false, false, "GEO recall on a map-update tile's added and moved edges"},
    {"geo_recall_unchanged", "", false, false, "GEO recall on a map-update tile's unchanged and retyped edges"},
    {"topo_recall_lane", "", false, false, "TOPO recall summed over the seeds on lane edges"},
    {"topo_recall_connector", "", false, false, "TOPO recall summed over the seeds on connector edges"},
    {"topo_recall_in_intersection", "", false, false, "TOPO recall over the seeds inside intersections"},
    {"topo_recall_outside_intersection", "", false, false, "TOPO recall over the seeds outside intersections"},
    {"topo_recall_changed", "", false, false, "TOPO recall over the seeds on changed edges"},
    {"topo_recall_unchanged", "", false, false, "TOPO recall over the seeds on unchanged edges"},
    {"change_recall", "", false, false,
     "map change: samples where current and prior map differ that the prediction follows the current map at"},
    {"change_recall_added", "", false, false, "change recall on added lanes' samples"},
    {"change_recall_removed", "", false, false, "change recall on removed lanes' samples"},
    {"change_recall_moved", "", false, false, "change recall on moved lanes' samples, old and new place"},
    {"change_precision", "", false, false, "changes the prediction claims against the prior that are real"},
    {"change_f1", "", false, false, "change F1"},
    {"false_change_rate", "", true, false, "samples the prior and current map share that the prediction drops"},
    {"unchanged_precision", "", false, false, "predicted samples away from every change that lie on the map"},
    {"unchanged_recall", "", false, false, "map samples away from every change that the prediction has"}};
constexpr const char* kCountNames[kCountCount] = {"missing_prediction",
                                                  "gt_self_loops_dropped",
                                                  "gt_duplicate_edges_dropped",
                                                  "pred_self_loops_dropped",
                                                  "pred_duplicate_edges_dropped",
                                                  "gt_px",
                                                  "pred_px",
                                                  "inter_px",
                                                  "union_px",
                                                  "geo_gt_samples",
                                                  "geo_pred_samples",
                                                  "geo_matched",
                                                  "topo_seeds",
                                                  "apls_gt_pairs",
                                                  "apls_pred_pairs",
                                                  "direction_pred_edges",
                                                  "direction_matched",
                                                  "direction_correct",
                                                  "sda_gt_splits",
                                                  "sda_pred_splits",
                                                  "sda20_matched",
                                                  "sda50_matched",
                                                  "jtopo_seeds",
                                                  "geo_gt_samples_lane",
                                                  "geo_gt_samples_connector",
                                                  "geo_gt_samples_in_intersection",
                                                  "geo_gt_samples_outside_intersection",
                                                  "geo_gt_samples_changed",
                                                  "geo_gt_samples_unchanged",
                                                  "geo_matched_lane",
                                                  "geo_matched_connector",
                                                  "geo_matched_in_intersection",
                                                  "geo_matched_outside_intersection",
                                                  "geo_matched_changed",
                                                  "geo_matched_unchanged",
                                                  "change_samples",
                                                  "change_detected",
                                                  "change_samples_added",
                                                  "change_detected_added",
                                                  "change_samples_removed",
                                                  "change_detected_removed",
                                                  "change_samples_moved",
                                                  "change_detected_moved",
                                                  "change_claims",
                                                  "change_claims_true",
                                                  "prior_kept_samples",
                                                  "false_changes",
                                                  "unchanged_pred_samples",
                                                  "unchanged_pred_on_map",
                                                  "unchanged_gt_samples",
                                                  "unchanged_gt_found"};

void set_apls(MetricValues& v, int first, const detail::AplsResult& r) {
  v[first] = r.apls;
  v[first + 1] = r.gt_to_pred;
  v[first + 2] = r.pred_to_gt;
}
// A file's checks (check_graph: finite values, indices, the scoring limits) on a graph given
// in memory: whichever way a graph reaches the scorer, its cost is bounded and no NaN or
// infinity reaches a grid cast.
void check_limits(const Graph& g, const std::string& key, const std::string& role) {
  const Issues issues = check_graph(g, key, role);
  if (!issues.empty()) throw DataError("", issues.items().front().subject, issues.items().front().message);
}

// Split detection at UrbanLaneGraph's two radii, which are part of the metrics' names (not
// parameters). As its calc_sda: undefined without a ground-truth split, 0 when the
// prediction has none. The assignment's cost (rows² × columns) is metered like a search's.
void set_sda(const CleanGraph& g, const CleanGraph& p, detail::WorkMeter& meter, TileMeasurement& t) {
  constexpr int kSdaMetrics[2][2] = {{kSda20Precision, kSda20Recall}, {kSda50Precision, kSda50Recall}};
  constexpr int kSdaMatched[2] = {kSda20Matched, kSda50Matched};
  const detail::SdaResult r = detail::compute_sda(g, p, {20.0, 50.0}, meter);
  t.counts[kSdaGtSplits] = r.gt_splits;
  t.counts[kSdaPredSplits] = r.pred_splits;
  for (int k = 0; k < 2; ++k) {
    t.counts[kSdaMatched[k]] = r.matched[static_cast<size_t>(k)];
    if (r.gt_splits == 0) continue;
    const auto tp = static_cast<double>(r.matched[static_cast<size_t>(k)]);
    t.values[kSdaMetrics[k][0]] = r.pred_splits == 0 ? 0.0 : tp / static_cast<double>(r.pred_splits);
    t.values[kSdaMetrics[k][1]] = tp / static_cast<double>(r.gt_splits);
  }
}

// Junction TOPO and the per-class recalls, from GEO/TOPO's result.
void set_geo_topo_v2(const detail::GeoTopoResult& r, TileMeasurement& t) {
  t.values[kJtopoPrecision] = r.jtopo_precision;
  t.values[kJtopoRecall] = r.jtopo_recall;
  t.values[kJtopoF1] = r.jtopo_f1;
  t.counts[kJtopoSeeds] = r.jtopo_seeds;
  for (int k = 0; k < kEdgeClassCount; ++k) {
    t.values[kGeoRecallLane + k] = r.geo_recall_by_class[k];
    t.values[kTopoRecallLane + k] = r.topo_recall_by_class[k];
    t.counts[kGeoGtSamplesLane + k] = r.gt_samples_by_class[k];
    t.counts[kGeoMatchedLane + k] = r.matched_by_class[k];
  }
}

// The change metrics of a map-update tile (a ground truth with a prior graph; undefined on
// every other tile), values from counts.
void set_changes(const detail::ChangeResult& r, TileMeasurement& t) {
  const auto as = [](int64_t n) { return static_cast<double>(n); };
  const std::pair<const detail::ChangeResult::Kind*, std::array<int, 3>> kinds[] = {
      {&r.all, {kChangeRecall, kChangeSamples, kChangeDetected}},
      {&r.added, {kChangeRecallAdded, kChangeSamplesAdded, kChangeDetectedAdded}},
      {&r.removed, {kChangeRecallRemoved, kChangeSamplesRemoved, kChangeDetectedRemoved}},
      {&r.moved, {kChangeRecallMoved, kChangeSamplesMoved, kChangeDetectedMoved}}};
  for (const auto& [kind, slots] : kinds) {
    t.values[slots[0]] = detail::ratio(as(kind->detected), as(kind->samples));
    t.counts[slots[1]] = kind->samples;
    t.counts[slots[2]] = kind->detected;
  }
  t.values[kChangePrecision] = detail::ratio(as(r.true_claims), as(r.claims));
  t.values[kChangeF1] = detail::f1_of(t.values[kChangePrecision], t.values[kChangeRecall]);
  t.values[kFalseChangeRate] = detail::ratio(as(r.false_changes), as(r.prior_kept));
  t.values[kUnchangedPrecision] = detail::ratio(as(r.unchanged_pred_on_map), as(r.unchanged_pred));
  t.values[kUnchangedRecall] = detail::ratio(as(r.unchanged_gt_found), as(r.unchanged_gt));
  t.counts[kChangeClaims] = r.claims;
  t.counts[kChangeClaimsTrue] = r.true_claims;
  t.counts[kPriorKeptSamples] = r.prior_kept;
  t.counts[kFalseChanges] = r.false_changes;
  t.counts[kUnchangedPredSamples] = r.unchanged_pred;
  t.counts[kUnchangedPredOnMap] = r.unchanged_pred_on_map;
  t.counts[kUnchangedGtSamples] = r.unchanged_gt;
  t.counts[kUnchangedGtFound] = r.unchanged_gt_found;
}

// APLS and GEO/TOPO: the metrics whose searches the work meter bounds.
void measure_searched(const CleanGraph& g, const CleanGraph& p, const MetricParams& params, detail::WorkMeter& meter,
                      TileMeasurement& t) {
  MetricValues& v = t.values;
  Counts& c = t.counts;
  const detail::AplsFamily apls = detail::compute_apls(g, p, params, meter);
  set_apls(v, kApls, apls.undirected);
  set_apls(v, kAplsDirected, apls.directed);
  set_apls(v, kAplsStrict, apls.strict);
  c[kAplsGtPairs] = apls.undirected.gt_pairs;
  c[kAplsPredPairs] = apls.undirected.pred_pairs;

  const detail::GeoTopoResult gt_r = detail::compute_geo_topo(g, p, params, meter);
  v[kGeoPrecision] = gt_r.geo_precision;
  v[kGeoRecall] = gt_r.geo_recall;
  v[kGeoF1] = gt_r.geo_f1;
  v[kTopoPrecision] = gt_r.topo_precision;
  v[kTopoRecall] = gt_r.topo_recall;
  v[kTopoF1] = gt_r.topo_f1;
  v[kTopoDirectedPrecision] = gt_r.topo_directed_precision;
  v[kTopoDirectedRecall] = gt_r.topo_directed_recall;
  v[kTopoDirectedF1] = gt_r.topo_directed_f1;
  c[kGeoGtSamples] = gt_r.gt_samples;
  c[kGeoPredSamples] = gt_r.pred_samples;
  c[kGeoMatched] = gt_r.matched;
  c[kTopoSeeds] = gt_r.seeds;
  set_geo_topo_v2(gt_r, t);
}

}  // namespace

const MetricInfo& metric_info(int metric) {
  NSG_CHECK(metric >= 0 && metric < kMetricCount, InternalError, "", "", "metric index");
  return kMetrics[metric];
}

const char* metric_name(int metric) { return metric_info(metric).name; }

std::string metric_list(const std::string& format) {
  NSG_CHECK(format == "md" || format == "json", ConfigError, "", "--format", "md or json for --list-metrics");
  if (format == "json") {
    nlohmann::ordered_json out = nlohmann::ordered_json::array();
    for (const MetricInfo& m : kMetrics)
      out.push_back({{"name", m.name},
                     {"unit", m.unit},
                     {"better", m.lower_is_better ? "lower" : "higher"},
                     {"leaderboard", m.leaderboard},
                     {"description", m.description}});
    return out.dump(2) + "\n";
  }
  std::string out = "| metric | unit | better | leaderboard | what it measures |\n| --- | --- | --- | --- | --- |\n";
  for (const MetricInfo& m : kMetrics)
    out += strprintf("| `%s` | %s | %s | %s | %s |\n", m.name, *m.unit ? m.unit : "fraction",
                     m.lower_is_better ? "lower ↓" : "higher ↑", m.leaderboard ? "yes" : "", m.description);
  return out;
}
const std::vector<HeadlineMetric>& headline_metrics() {
  static const std::vector<HeadlineMetric> kHeadline = {
      {kApls, "APLS", 4},
      {kAplsDirected, "APLS dir.", 4},
      {kAplsStrict, "APLS strict", 4},
      {kDirectionAccuracy, "Dir. acc.", 4},
      {kF1, "F1", 4},
      {kIou, "IoU", 4},
      {kChamferMeanM, "mean Chamfer (m)", 3},
      {kGeoF1, "GEO F1", 4},
      {kTopoF1, "TOPO F1", 4},
  };
  return kHeadline;
}

const char* count_name(int count) {
  NSG_CHECK(count >= 0 && count < kCountCount, InternalError, "", "", "count index");
  return kCountNames[count];
}

TileMeasurement measure(const std::string& key, const Graph& gt, const Graph* pred, const MetricParams& params) {
  check_limits(gt, key, "ground truth");
  if (gt.prior != nullptr) check_limits(*gt.prior, key, "prior ground truth");
  if (pred != nullptr) check_limits(*pred, key, "prediction");
  const Graph empty;
  CleanGraph g, p, prior;
  try {
    g = clean_graph(gt);
    p = clean_graph(pred != nullptr ? *pred : empty);
    if (gt.prior != nullptr) prior = clean_graph(*gt.prior);
  } catch (const DataError& e) {
    throw DataError("", key + "/" + e.record(), e.expected());
  }
  TileMeasurement t;
  t.key = key;
  MetricValues& v = t.values;
  Counts& c = t.counts;
  c[kMissingPrediction] = pred == nullptr ? 1 : 0;
  c[kGtSelfLoopsDropped] = g.self_loops_dropped;
  c[kGtDuplicateEdgesDropped] = g.duplicate_edges_dropped;
  c[kPredSelfLoopsDropped] = p.self_loops_dropped;
  c[kPredDuplicateEdgesDropped] = p.duplicate_edges_dropped;

  const int64_t work_limit = validate::SubmissionLimits{}.max_search_work_per_tile;
  detail::WorkMeter meter(work_limit);
  try {
    measure_searched(g, p, params, meter, t);
    // The split assignment has a budget of its own, of the same size: its cost does not eat
    // into the searches' margin (docs/scoring-limits.md).
    detail::WorkMeter assignment_meter(work_limit);
    set_sda(g, p, assignment_meter, t);
    // The change metrics' comparisons likewise (a prediction against two maps).
    if (gt.prior != nullptr) {
      detail::WorkMeter change_meter(work_limit);
      set_changes(detail::compute_changes(g, prior, p, params, change_meter), t);
    }
  } catch (const detail::OverBudget&) {
    throw SearchWorkExceeded(
        "", "prediction:/tiles/" + validate::json_pointer_token(key),
        strprintf(
            "a prediction whose APLS, TOPO, split-assignment and map-change searches against this tile's ground truth "
            "take at most %lld units of work (about 9 ns each); this one reached the "
            "limit before they ended: it is too large or too connected where the "
            "ground truth is connected (docs/scoring-limits.md)",
            static_cast<long long>(work_limit)));
  }
  t.search_work = meter.used();

  const detail::DirectionResult dir = detail::compute_direction(g, p, params);
  v[kDirectionAccuracy] = dir.accuracy;
  v[kDirectionAccuracyLengthWeighted] = dir.accuracy_length_weighted;
  v[kDirectionMatchedFraction] = dir.matched_fraction;
  c[kDirectionPredEdges] = dir.pred_edges;
  c[kDirectionMatched] = dir.matched;
  c[kDirectionCorrect] = dir.correct;

  const detail::MaskResult mask = detail::compute_masks(g, p, params);
  c[kGtPx] = mask.gt_px;
  c[kPredPx] = mask.pred_px;
  c[kInterPx] = mask.inter_px;
  c[kUnionPx] = mask.union_px;
  v[kF1] = detail::ratio(2.0 * static_cast<double>(mask.inter_px), static_cast<double>(mask.gt_px + mask.pred_px));
  v[kIou] = detail::ratio(static_cast<double>(mask.inter_px), static_cast<double>(mask.union_px));

  const detail::ChamferResult ch = detail::compute_chamfer(g, p, params);
  v[kChamferPx2] = ch.px2;
  v[kChamferM2] = ch.m2;
  v[kChamferMeanM] = ch.mean_m;

  // Every metric is a finite number or undefined (docs/metrics.md); the limits keep the
  // inputs where that holds, and a value that still is not is a bug, never a report entry.
  for (int m = 0; m < kMetricCount; ++m)
    NSG_CHECK(!v[m] || std::isfinite(*v[m]), InternalError, "", key + "/" + metric_name(m),
              "a finite value or undefined");
  return t;
}

void Aggregate::add(const TileMeasurement& tile) {
  ++n_tiles;
  n_missing_predictions += tile.counts[kMissingPrediction];
  for (int m = 0; m < kMetricCount; ++m) {
    if (tile.values[m]) {
      value_sums[m] += *tile.values[m];
      ++n_defined[m];
    } else {
      ++n_undefined[m];
    }
  }
  for (int k = 0; k < kCountCount; ++k) count_sums[k] += tile.counts[k];
}

void Aggregate::merge(const Aggregate& other) {
  n_tiles += other.n_tiles;
  n_missing_predictions += other.n_missing_predictions;
  n_extra_predictions += other.n_extra_predictions;
  for (int m = 0; m < kMetricCount; ++m) {
    value_sums[m] += other.value_sums[m];
    n_defined[m] += other.n_defined[m];
    n_undefined[m] += other.n_undefined[m];
  }
  for (int k = 0; k < kCountCount; ++k) count_sums[k] += other.count_sums[k];
}

AggregateReport finalize(const Aggregate& a) {
  AggregateReport r;
  r.n_tiles = a.n_tiles;
  r.n_missing_predictions = a.n_missing_predictions;
  r.n_extra_predictions = a.n_extra_predictions;
  r.n_defined = a.n_defined;
  r.n_undefined = a.n_undefined;
  r.sums = a.count_sums;
  for (int m = 0; m < kMetricCount; ++m)
    r.mean[m] = detail::ratio(a.value_sums[m], static_cast<double>(a.n_defined[m]));
  const auto s = [&](int k) { return static_cast<double>(a.count_sums[k]); };
  r.pooled_f1 = detail::ratio(2.0 * s(kInterPx), s(kGtPx) + s(kPredPx));
  r.pooled_iou = detail::ratio(s(kInterPx), s(kUnionPx));
  r.pooled_geo_precision = detail::ratio(s(kGeoMatched), s(kGeoPredSamples));
  r.pooled_geo_recall = detail::ratio(s(kGeoMatched), s(kGeoGtSamples));
  r.pooled_geo_f1 = detail::ratio(2.0 * s(kGeoMatched), s(kGeoGtSamples) + s(kGeoPredSamples));
  r.pooled_change_recall = detail::ratio(s(kChangeDetected), s(kChangeSamples));
  r.pooled_change_precision = detail::ratio(s(kChangeClaimsTrue), s(kChangeClaims));
  r.pooled_false_change_rate = detail::ratio(s(kFalseChanges), s(kPriorKeptSamples));
  return r;
}

std::vector<std::pair<const char*, std::optional<double>>> pooled_values(const AggregateReport& a) {
  return {{"f1", a.pooled_f1},
          {"iou", a.pooled_iou},
          {"geo_precision", a.pooled_geo_precision},
          {"geo_recall", a.pooled_geo_recall},
          {"geo_f1", a.pooled_geo_f1},
          {"change_recall", a.pooled_change_recall},
          {"change_precision", a.pooled_change_precision},
          {"false_change_rate", a.pooled_false_change_rate}};
}

}  // namespace nsg::metrics

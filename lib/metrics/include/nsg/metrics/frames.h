#pragma once
// Scoring per-key-frame predictions (docs/metrics.md "Frames"): OpenLane-V2's lane metrics
// DET_l (mean AP over discrete-Fréchet thresholds 1, 2, 3 m with its distance relaxation)
// and TOP_ll (lane–lane topology mAP), computed as its evaluator computes them, and
// `lane_score` = (DET_l + sqrt(TOP_ll)) / 2 — OLS's lane terms, not OLS (nuScenes has no
// traffic elements). The ground truth is an `nsgraph frames` export, read only through its
// manifest; the predictions an OpenLane-V2 results document in JSON.
#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "nsg/core/issues.h"
#include "nsg/metrics/frames_documents.h"  // the documents: manifest, record, results
#include "nsg/metrics/graph.h"

namespace nsg::metrics {

inline constexpr const char* kFramesMetricsVersion = "3";

struct FramesReport {
  std::string split;
  int64_t frames = 0;                         // ground-truth frames scored
  int64_t missing_frames = 0;                 // without a prediction (scored as predicting nothing)
  int64_t extra_frames = 0;                   // predictions of no ground-truth frame (ignored)
  std::vector<std::string> missing_examples;  // up to 5, in ground-truth order
  int64_t gt_centerlines = 0;
  int64_t pred_centerlines = 0;
  std::array<double, 3> det_l_per_threshold{};  // AP at 1, 2, 3 m
  double det_l = 0.0;
  double top_ll = 0.0;
  double lane_score = 0.0;
  bool has_centerlines = true;  // false: the submission had lane segments only (DET_l etc. not reported)
  // OpenLane-V2 v2.1's lane-segment track (lanesegment/evaluation), when both the ground
  // truth (a version-2 export) and the predictions carry lane segments: DET_ls (mean AP over
  // 1, 2, 3 m of the relaxed lane-segment distance), DET_a (areas: mean AP over both
  // categories at 0.5, 1, 1.5 m Chamfer), TOP_lsls, and its 'score' (see docs/metrics.md).
  bool has_lane_segments = false;
  std::array<double, 3> det_ls_per_threshold{};
  double det_ls = 0.0;
  std::array<double, 2> det_a_per_category{};  // pedestrian crossing, road boundary
  double det_a = 0.0;
  double top_lsls = 0.0;
  double ls_score = 0.0;
  int64_t gt_lane_segments = 0, pred_lane_segments = 0, gt_areas = 0, pred_areas = 0;
  // nsgraph's own metrics (docs/metrics.md) on each frame's graph — centerline points as
  // nodes, consecutive points and links as edges, ego metres at 0.2 m a pixel — as macro
  // means over the frames where defined: apls, apls_directed, direction_accuracy, geo_f1,
  // topo_f1, topo_directed_f1 (metric_name order).
  std::vector<std::pair<std::string, std::optional<double>>> graph_means;
};

// A frame as nsgraph's graph (see FramesReport::graph_means): the truth's links where
// topology is 1, a prediction's where it is above 0.5.
Graph frame_graph(const FrameCenterlines& frame, bool truth);

// DET_l, TOP_ll and lane_score of `predictions` on `truth` (a missing prediction = none);
// with `graph_metrics` also nsgraph's own on each frame's graph (graph_means; about 20× the
// time of the rest: APLS searches every frame's graph). `max_seconds` (0 = none) is the
// wall-clock budget, as metrics::ScoreOptions::max_seconds is for tiles: checked before each
// frame's measurement, beyond it a ConfigError naming --max-seconds (exit 2).
FramesReport score_frames(const FrameSet& truth, const FrameSet& predictions, bool graph_metrics = false,
                          double max_seconds = 0);

// The records of `split` of an `nsgraph frames` export, through its manifest: every record
// listed for the split must be present with its size and (when `verify`) sha256. Keys are
// sample tokens; `token_by_identifier` (when given) receives each frame's OpenLane-V2
// identifier → its token (FrameRecord::identifier). IoError / ParseError / DataError naming
// the file.
FrameSet read_frames_ground_truth(const std::filesystem::path& export_dir, const std::string& split, bool verify,
                                  std::map<std::string, std::string>* token_by_identifier = nullptr);

// Renames the predictions keyed by an OpenLane-V2 identifier ("split/segment_id/timestamp")
// to the frame's sample token; keys that are neither stay (extra frames). Two predictions of
// one frame — a key twice, or its token and its identifier — are frames.results.duplicate
// issues naming both keys.
void key_results_by_token(FrameSet& predictions, const std::map<std::string, std::string>& token_by_identifier,
                          const std::string& results_label, Issues& issues);
// A ground-truth document {"frames": {key: {"lane_centerline": [{"points"}], "topology_lclc"}}}
// (the golden set's gt.json), keys in file order.
FrameSet read_frames_ground_truth_document(const std::filesystem::path& file);

// Each frame's Chamfer/Fréchet work (ground-truth points × predicted points) within
// limits.max_point_pairs_per_frame; frames.results.size issues naming the frame.
void check_frame_work(const FrameSet& truth, const FrameSet& predictions, const FrameResultsLimits& limits,
                      const std::string& results_label, Issues& issues);

// `nsgraph score --frames`: the ground truth (an export folder, its `split`, or a
// ground-truth document file) and a results file, read, checked and scored. `report` is
// empty when the results have problems (`issues`; the CLI's exit 1); bad ground truth throws.
struct FramesScoreInput {
  std::filesystem::path ground_truth;
  std::string split = "test";
  bool verify = true;
  bool graph_metrics = false;  // --graph-metrics
  std::filesystem::path results;
  FrameResultsLimits limits;
  // Wall-clock budget of scoring the frames (--max-seconds, the default of
  // metrics::ScoreOptions; score_frames); 0 = none.
  double max_seconds = 3600;
};
struct ScoredFrames {
  std::optional<FramesReport> report;
  Issues issues;
};
ScoredFrames score_frames_submission(const FramesScoreInput& input);

nlohmann::ordered_json frames_report_to_json(const FramesReport& r);

}  // namespace nsg::metrics

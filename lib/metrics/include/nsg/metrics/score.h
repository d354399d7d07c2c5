#pragma once
// Scoring a submission against a ground truth: tiles in parallel, merged in key order,
// and the report in JSON (schemas/v1/score-report.schema.json), Markdown and CSV.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nsg/metrics/graph.h"
#include "nsg/metrics/measure.h"
#include "nsg/metrics/params.h"

namespace nsg::metrics {

struct ScoreOptions {
  MetricParams params;
  int threads = 1;  // 0 = all cores; output never depends on it
  // Wall-clock budget of scoring the tiles, the host's last line of defence (every tile
  // is bounded by the limits; a run of many is bounded by this): checked before each tile,
  // so a run stops within one tile's time per thread of it. 0 = none.
  double max_seconds = 3600;
  bool progress = false;  // a progress line over the tiles on stderr (the CLI's); no output depends on it
  void validate() const;
};

struct ScoreReport {
  MetricParams params;
  std::vector<TileMeasurement> tiles;      // GT keys, sorted
  std::vector<std::string> missing_tiles;  // GT keys absent from the submission
  std::vector<std::string> extra_tiles;    // submission keys not in the GT (ignored)
  AggregateReport aggregate;
  // Free-form provenance copied into the JSON report (paths, split).
  std::string ground_truth, submission, split;
  // How the ground truth was established: "sha256" (a dataset's split, every shard hashed
  // against its manifest), "sizes" (--no-verify: listed and sized, not hashed), "file" (a
  // submission-format file), "memory" (the caller's own document).
  std::string ground_truth_verification;
  // What the score was computed from and with (receipt.h; set by score_submission, null
  // for a bare score()).
  nlohmann::json receipt;
  // Per rung of an observation ladder (rungs.h: rungs_to_json), null when the submission
  // holds no rung tile.
  nlohmann::json rungs;
};

ScoreReport score(const GraphSet& gt, const GraphSet& pred, const ScoreOptions& options);

nlohmann::json measurement_to_json(const TileMeasurement& tile);
nlohmann::json aggregate_to_json(const AggregateReport& aggregate);
nlohmann::json report_to_json(const ScoreReport& report);
// Paper-style table (APLS, direction, F1, IoU, Chamfer, GEO, TOPO) plus counts.
std::string report_to_markdown(const ScoreReport& report);
// One row per tile: key, every metric (empty = undefined), every count.
std::string report_to_csv(const ScoreReport& report);

}  // namespace nsg::metrics

// `nsgraph score`: the benchmark metrics of a submission against a ground truth
// (docs/metrics.md). Problems of the submission (not JSON, beyond the size, value-count or
// nesting limits, or invalid) exit 1; an unreadable submission or bad ground truth exits 2.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>

#include "commands.h"
#include "limit_flags.h"
#include "nsg/core/atomic_file.h"
#include "nsg/core/error.h"
#include "nsg/core/log.h"
#include "nsg/core/strings.h"
#include "nsg/metrics/frames.h"
#include "nsg/metrics/io.h"
#include "nsg/metrics/receipt.h"
#include "nsg/metrics/score.h"
#include "nsg/metrics/score_submission.h"

namespace nsg::cli {
namespace {

struct ScoreCliOptions {
  std::string ground_truth;
  std::string submission;
  std::string out;              // JSON report file ("" = none)
  std::string format = "json";  // what stdout prints: json | md | csv
  std::string verify_receipt;   // a score report (or receipt) to recompute and compare
  bool frames = false;          // --frames: an `nsgraph frames` export and an OpenLane-V2 results file
  bool graph_metrics = false;   // --graph-metrics (with --frames)
  bool list_metrics = false;    // --list-metrics: the metric table (md or json) and exit
  bool list_counts = false;     // --list-counts: the per-tile count names (JSON) and exit
  metrics::SubmissionScoreOptions lib;

  void validate() const {
    // Required unless --list-metrics or --list-counts (which read neither).
    NSG_CHECK(!ground_truth.empty(), ConfigError, "", "--ground-truth", "a dataset folder or a ground-truth file");
    NSG_CHECK(!submission.empty(), ConfigError, "", "--submission", "a submission file");
    NSG_CHECK(format == "json" || format == "md" || format == "csv", ConfigError, "", "--format",
              "json, md or csv, got '" + format + "'");
  }
};

// The recorded report or receipt, read as a stranger's file: within the submission limits
// (size, value count, depth, no repeated key).
nlohmann::json read_receipt_file(const std::string& file) {
  std::error_code ec;
  NSG_CHECK(std::filesystem::is_regular_file(file, ec), IoError, file, "--verify-receipt",
            "a score report or receipt file (score --out writes one): no such file");
  Issues issues;
  const std::optional<nlohmann::json> doc = validate::read_submission(file, validate::SubmissionLimits{}, issues);
  if (!doc) throw ParseError(file, "--verify-receipt", "a score report or receipt: " + issues.items().front().message);
  return *doc;
}

// --verify-receipt: recompute with the verifier's own options and limits (the defaults,
// --no-verify and the limit flags given here; a receipt verifies, it never configures),
// on the split the receipt names unless --split is given, then say "same" or what
// differs. Exit 0 same, 1 differs (or the submission is refused now), 2 unreadable.
int run_verify_receipt(const ScoreCliOptions& o) {
  const nlohmann::json recorded = read_receipt_file(o.verify_receipt);
  const metrics::Receipt receipt = metrics::read_receipt(recorded, o.verify_receipt);
  metrics::SubmissionScoreOptions lib = o.lib;
  if (lib.split.empty()) lib.split = receipt.options_split;
  const metrics::ScoredSubmission scored = metrics::score_submission(metrics::ScoreSource::file(o.ground_truth),
                                                                     metrics::ScoreSource::file(o.submission), lib);
  if (!scored.scored()) {
    std::fputs(scored.issues.format().c_str(), stderr);
    std::printf("receipt %s: differs\n  the submission is refused under this verifier's limits (%zu problem(s))\n",
                printable_text(o.verify_receipt).c_str(), scored.issues.size());
    return kExitProblems;
  }
  const nlohmann::json recomputed = metrics::report_to_json(scored.report);
  if (!o.out.empty()) write_file_atomic(o.out, recomputed.dump(1) + "\n");
  const metrics::ReceiptComparison c = metrics::compare_receipt(recorded, recomputed, o.verify_receipt);
  std::printf("receipt %s: %s\n", printable_text(o.verify_receipt).c_str(), c.same() ? "same" : "differs");
  for (const std::string& d : c.differences) std::printf("  %s\n", printable_text(d).c_str());
  for (const std::string& n : c.notes) std::printf("  note: %s\n", printable_text(n).c_str());
  return c.same() ? kExitOk : kExitProblems;
}

// --frames: DET_l, TOP_ll and lane_score of per-key-frame predictions, and the lane-segment
// track's DET_ls, DET_a, TOP_lsls and score when they carry lane segments (docs/metrics.md "Frames").
int run_score_frames(const ScoreCliOptions& o) {
  NSG_CHECK(o.verify_receipt.empty(), ConfigError, "", "--verify-receipt", "tile scoring (not with --frames)");
  NSG_CHECK(o.format != "csv", ConfigError, "", "--format", "json or md with --frames (no per-tile table)");
  metrics::FramesScoreInput in;
  in.ground_truth = o.ground_truth;
  in.split = o.lib.split.empty() ? std::string("test") : o.lib.split;
  in.verify = o.lib.verify_ground_truth;
  in.graph_metrics = o.graph_metrics;
  in.results = o.submission;
  in.limits.max_file_bytes = o.lib.limits.max_file_bytes;
  in.max_seconds = o.lib.score.max_seconds;  // the budget tile scoring has (beyond it: exit 2)
  const metrics::ScoredFrames scored = metrics::score_frames_submission(in);
  if (!scored.report) {
    std::fputs(scored.issues.format().c_str(), stderr);
    log::error(strprintf("%zu problem(s) in results %s; not scored", scored.issues.size(), o.submission.c_str()));
    return kExitProblems;
  }
  const metrics::FramesReport& r = *scored.report;
  const nlohmann::ordered_json json = metrics::frames_report_to_json(r);
  if (!o.out.empty()) write_file_atomic(o.out, json.dump(1) + "\n");
  if (o.format == "md") {
    if (r.has_centerlines)
      std::printf(
          "| frames | DET_l | DET_l@1m | DET_l@2m | DET_l@3m | TOP_ll | lane_score |\n| --- | --- | --- | --- | --- | "
          "--- | --- |\n| %lld | %.4f | %.4f | %.4f | %.4f | %.4f | %.4f |\n",
          static_cast<long long>(r.frames), r.det_l, r.det_l_per_threshold[0], r.det_l_per_threshold[1],
          r.det_l_per_threshold[2], r.top_ll, r.lane_score);
    if (r.has_lane_segments)
      std::printf(
          "%s| frames | DET_ls | DET_a | DET_a crossing | DET_a boundary | TOP_lsls | score |\n| --- | --- | --- | --- "
          "| --- | --- | --- |\n| %lld | %.4f | %.4f | %.4f | %.4f | %.4f | %.4f |\n",
          r.has_centerlines ? "\n" : "", static_cast<long long>(r.frames), r.det_ls, r.det_a, r.det_a_per_category[0],
          r.det_a_per_category[1], r.top_lsls, r.ls_score);
  } else {
    std::fputs((json.dump(1) + "\n").c_str(), stdout);
  }
  std::string said =
      strprintf("scored %lld frames (%lld without a prediction, %lld extra)", static_cast<long long>(r.frames),
                static_cast<long long>(r.missing_frames), static_cast<long long>(r.extra_frames));
  if (r.has_centerlines)
    said += strprintf(": DET_l %.4f, TOP_ll %.4f, lane_score %.4f", r.det_l, r.top_ll, r.lane_score);
  if (r.has_lane_segments)
    said += strprintf("%s DET_ls %.4f, DET_a %.4f, TOP_lsls %.4f, score %.4f", r.has_centerlines ? ";" : ":", r.det_ls,
                      r.det_a, r.top_lsls, r.ls_score);
  log::info(said);
  return kExitOk;
}

int run_score(const ScoreCliOptions& o) {
  if (o.list_metrics) {
    std::fputs(metrics::metric_list(o.format == "json" ? "json" : "md").c_str(), stdout);
    return kExitOk;
  }
  if (o.list_counts) {
    nlohmann::json names = nlohmann::json::array();
    for (int k = 0; k < metrics::kCountCount; ++k) names.push_back(metrics::count_name(k));
    std::fputs((names.dump(2) + "\n").c_str(), stdout);
    return kExitOk;
  }
  o.validate();
  if (o.frames) return run_score_frames(o);
  if (!o.verify_receipt.empty()) return run_verify_receipt(o);
  const metrics::ScoredSubmission scored = metrics::score_submission(metrics::ScoreSource::file(o.ground_truth),
                                                                     metrics::ScoreSource::file(o.submission), o.lib);
  if (!scored.scored()) {
    std::fputs(scored.issues.format().c_str(), stderr);
    log::error(strprintf("%zu problem(s) in submission %s; not scored", scored.issues.size(), o.submission.c_str()));
    return kExitProblems;
  }
  const metrics::ScoreReport& report = scored.report;

  const nlohmann::json json = metrics::report_to_json(report);
  if (!o.out.empty()) write_file_atomic(o.out, json.dump(1) + "\n");
  const std::string shown = o.format == "md"    ? metrics::report_to_markdown(report)
                            : o.format == "csv" ? metrics::report_to_csv(report)
                                                : json.dump(1) + "\n";
  std::fputs(shown.c_str(), stdout);

  const metrics::AggregateReport& a = report.aggregate;
  auto show = [](const std::optional<double>& v) { return v ? strprintf("%.4f", *v) : std::string("undefined"); };
  log::info(strprintf("scored %lld tiles (%lld missing, %lld extra): APLS %s, F1 %s, TOPO F1 %s",
                      static_cast<long long>(a.n_tiles), static_cast<long long>(a.n_missing_predictions),
                      static_cast<long long>(a.n_extra_predictions), show(a.mean[metrics::kApls]).c_str(),
                      show(a.mean[metrics::kF1]).c_str(), show(a.mean[metrics::kTopoF1]).c_str()));
  return kExitOk;
}

}  // namespace

void add_score_command(CLI::App& parent, Context& ctx) {
  auto opts = std::make_shared<ScoreCliOptions>();
  opts->lib.score.progress = true;
  CLI::App* cmd =
      parent.add_subcommand("score", "Score a submission against a ground truth (docs/metrics.md, metrics v" +
                                         std::string(metrics::kMetricsVersion) + ")");
  cmd->add_option("--ground-truth", opts->ground_truth,
                  "Dataset folder (its tiles of --split) or a file in the submission format (required)");
  cmd->add_option("--submission", opts->submission,
                  "Submission JSON (schemas/v1/submission.schema.json): a file, or a pipe / /dev/stdin (required)");
  opts->lib.split.clear();  // "" = from the submission's keys
  cmd->add_option("--split", opts->lib.split,
                  "Split of a dataset ground truth (default: the split the submission's keys are tiles of; with "
                  "--frames: test)");
  cmd->add_flag("--frames", opts->frames,
                "Per-key-frame scoring: --ground-truth is an `nsgraph frames` export (its --split) and --submission an "
                "OpenLane-V2 results JSON; DET_l, TOP_ll, lane_score (docs/metrics.md \"Frames\")");
  cmd->add_flag("--graph-metrics", opts->graph_metrics,
                "With --frames: also nsgraph's APLS, direction, GEO and TOPO on each frame's graph (nsgraph_metrics; "
                "about 20x slower)");
  cmd->add_flag("--no-verify{false}", opts->lib.verify_ground_truth,
                "Do not hash a dataset's shards against its manifest (presence, sizes and unlisted shards are still "
                "checked); the report's ground_truth_verification says \"sizes\"");
  cmd->add_option("--out", opts->out, "Write the JSON report here (atomically)");
  cmd->add_option("--verify-receipt", opts->verify_receipt,
                  "A score report (or its receipt) to verify: recompute from --ground-truth and --submission with "
                  "this command's own options and limits (never the receipt's), print \"same\" or what differs "
                  "(exit 0 / 1)");
  cmd->add_flag("--list-metrics", opts->list_metrics,
                "Print every metric (name, unit, which way is better, what it measures) and exit: a Markdown table, "
                "or JSON with --format json");
  cmd->add_flag("--list-counts", opts->list_counts,
                "Print the names of the per-tile counts (the integers that explain the metrics) as JSON and exit");
  cmd->add_option("--format", opts->format,
                  "What score prints on stdout: json, md (paper-style table) or csv (per tile)")
      ->capture_default_str();
  add_threads_option(cmd, opts->lib.score.threads);
  cmd->add_option("--max-seconds", opts->lib.score.max_seconds,
                  "Wall-clock budget of scoring the tiles; beyond it the run stops, exit 2 (0 = none)")
      ->capture_default_str();
  cmd->add_option("--schemas", opts->lib.schemas_dir, "Folder of the published schemas (default: installed/source)");
  add_submission_limit_flags(cmd, opts->lib.limits);
  cmd->footer(submission_limits_footer(opts->lib.limits));
  cmd->callback([opts, &ctx]() { ctx.run = [opts]() { return run_score(*opts); }; });
}

}  // namespace nsg::cli

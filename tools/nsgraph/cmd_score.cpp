// `nsgraph score`: the benchmark metrics of a submission against a ground truth
// (docs/metrics.md). Problems of the submission (not JSON, beyond the size, value-count or
// nesting limits, or invalid) exit 1; an unreadable submission or bad ground truth exits 2.
#include <cstdio>
#include <memory>
#include <optional>

#include "commands.h"
#include "nsg/core/atomic_file.h"
#include "nsg/core/error.h"
#include "nsg/core/log.h"
#include "nsg/core/strings.h"
#include "nsg/metrics/io.h"
#include "nsg/metrics/score.h"
#include "nsg/metrics/score_submission.h"

namespace nsg::cli {
namespace {

struct ScoreCliOptions {
  std::string ground_truth;
  std::string submission;
  std::string out;              // JSON report file ("" = none)
  std::string format = "json";  // what stdout prints: json | md | csv
  metrics::SubmissionScoreOptions lib;

  void validate() const {
    NSG_CHECK(format == "json" || format == "md" || format == "csv", ConfigError, "", "--format",
              "json, md or csv, got '" + format + "'");
  }
};

int run_score(const ScoreCliOptions& o) {
  o.validate();
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
  CLI::App* cmd = parent.add_subcommand("score", "Score a submission against a ground truth (docs/metrics.md v1)");
  cmd->add_option("--ground-truth", opts->ground_truth,
                  "Dataset folder (its tiles of --split) or a file in the submission format")
      ->required();
  cmd->add_option("--submission", opts->submission,
                  "Submission JSON (schemas/v1/submission.schema.json): a file, or a pipe / /dev/stdin")
      ->required();
  cmd->add_option("--split", opts->lib.split, "Split of a dataset ground truth")->capture_default_str();
  cmd->add_flag("--no-verify{false}", opts->lib.verify_ground_truth,
                "Do not hash a dataset's shards against its manifest (presence, sizes and unlisted shards are still "
                "checked); the report's ground_truth_verification says \"sizes\"");
  cmd->add_option("--out", opts->out, "Write the JSON report here (atomically)");
  cmd->add_option("--format", opts->format, "What stdout prints: json, md (paper-style table) or csv (per tile)")
      ->capture_default_str();
  cmd->add_option("--threads", opts->lib.score.threads, "Worker threads (0 = all cores); output does not depend on it")
      ->capture_default_str();
  cmd->add_option("--schemas", opts->lib.schemas_dir, "Folder of the published schemas (default: installed/source)");
  const validate::SubmissionLimits& limits = opts->lib.limits;
  cmd->footer(strprintf(
      "Limits (a submission beyond them is refused, exit 1, before scoring): a file or stream (--submission may be a\n"
      "pipe, e.g. /dev/stdin) of at most %lld MiB; per tile at most %lld nodes, %lld edges and %.0f px of total edge\n"
      "length, and a shortest-path work (per connected piece: nodes x (nodes + 2 x edges)) of at most %lld, i.e.\n"
      "about 1 800 nodes in one connected piece. They bound the scoring time: an adversarial tile at the limits\n"
      "scores in under 2 s on one core (docs/scoring-limits.md). Real 256-px tiles hold 100-1500 nodes.",
      static_cast<long long>(limits.max_file_bytes >> 20), static_cast<long long>(limits.max_nodes_per_tile),
      static_cast<long long>(limits.max_edges_per_tile), limits.max_edge_length_px_per_tile,
      static_cast<long long>(limits.max_path_work_per_tile)));
  cmd->callback([opts, &ctx]() { ctx.run = [opts]() { return run_score(*opts); }; });
}

}  // namespace nsg::cli

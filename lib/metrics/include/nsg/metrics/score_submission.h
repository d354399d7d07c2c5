#pragma once
// `nsgraph score` in one call, shared by the CLI, the Python binding and the report page:
// check the submission (validate's limits, the schema and the structural rules), load the
// ground truth, score, and stamp the report with where its inputs came from.
#include <filesystem>
#include <map>
#include <optional>
#include <string>

#include "nsg/core/issues.h"
#include "nsg/metrics/graph.h"
#include "nsg/metrics/score.h"
#include "nsg/validate/submission.h"

namespace nsg::metrics {

// A submission or a ground truth: a path (a file or a pipe; a ground truth may also be a
// dataset folder) or submission-format JSON text in memory.
struct ScoreSource {
  std::filesystem::path path;       // read when `text` is absent
  std::optional<std::string> text;  // the document itself
  std::string label;                // names it in issues and the report ("" = the path)

  static ScoreSource file(const std::filesystem::path& path) { return {path, std::nullopt, path.string()}; }
  static ScoreSource memory(std::string text, std::string label) { return {{}, std::move(text), std::move(label)}; }
};

struct SubmissionScoreOptions {
  ScoreOptions score;  // metric parameters and threads
  // The split of a dataset-folder ground truth; "" = the one split the submission's keys
  // are tiles of (refused as submission.keys when they fall in none or in several). A
  // file or in-memory ground truth has no splits: "" records "test", as before.
  std::string split = "test";
  std::filesystem::path schemas_dir;  // "" = validate::find_schemas_dir()
  validate::SubmissionLimits limits;  // for the submission and a ground-truth file alike
  bool verify_ground_truth = true;    // hash a dataset's shards against its manifest
  void validate() const;              // ConfigError naming the option
};

struct ScoredSubmission {
  Issues issues;       // non-empty: the submission was refused and nothing was scored
  GraphSet graphs;     // the submission's tiles (when scored)
  ScoreReport report;  // stamped with the labels of both sources and the split
  // An observation ladder's rungs (rungs.h): rung k's tiles scored under their ground-truth
  // keys (the report's tile view shows them per tile); empty without rung keys.
  std::map<int, ScoreReport> rung_reports;
  bool scored() const { return issues.empty(); }
};

// The submission's problems come back as issues (the CLI's exit 1); an unreadable file, a
// bad ground truth or bad options throw (exit 2). The ground truth is read only when the
// submission passes. In-memory ground truth is parsed strictly but not limit-checked: it
// is the caller's own data.
ScoredSubmission score_submission(const ScoreSource& ground_truth, const ScoreSource& submission,
                                  const SubmissionScoreOptions& options);

}  // namespace nsg::metrics

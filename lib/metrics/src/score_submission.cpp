#include "nsg/metrics/score_submission.h"

#include <algorithm>
#include <chrono>

#include "nsg/core/error.h"
#include "nsg/core/log.h"
#include "nsg/core/json.h"
#include "nsg/core/sha256.h"
#include "nsg/core/strings.h"
#include "nsg/io/dataset.h"
#include "nsg/metrics/io.h"
#include "nsg/metrics/receipt.h"
#include "nsg/metrics/rungs.h"
#include "nsg/metrics/submission_input.h"

namespace nsg::metrics {

void SubmissionScoreOptions::validate() const { score.validate(); }

namespace {

// The split to score: the one given, else the one split of a dataset ground truth whose
// shards' key ranges hold the submission's keys. nullopt (and an issue) when they fall in
// no split or in several: the user says which with --split.
std::optional<std::string> split_to_score(const ScoreSource& truth, const GraphSet& graphs, const std::string& given,
                                          const std::string& label, Issues& issues) {
  if (!given.empty()) return given;
  if (truth.text || !std::filesystem::is_directory(truth.path) || graphs.empty()) return std::string("test");
  std::vector<std::string> keys;
  for (const auto& kv : graphs) keys.push_back(kv.first);
  std::string why;
  const std::optional<std::string> split = io::Dataset::open(truth.path).split_of_keys(keys, why);
  if (split) log::info("split '" + *split + "' (the split the submission's keys are tiles of)");
  else issues.error("submission.keys", label, "keys of one split of the dataset, to know which to score: " + why);
  return split;
}

}  // namespace

ScoredSubmission score_submission(const ScoreSource& ground_truth, const ScoreSource& submission,
                                  const SubmissionScoreOptions& options) {
  options.validate();
  ScoredSubmission out;
  CheckedSubmission checked =
      submission.text ? check_submission_text(*submission.text, submission.label, options.schemas_dir, options.limits)
                      : check_submission_file(submission.path, options.schemas_dir, options.limits);
  if (!checked.issues.empty()) {
    out.issues = std::move(checked.issues);
    return out;
  }
  out.graphs = std::move(checked.graphs);
  const std::optional<std::string> split =
      split_to_score(ground_truth, out.graphs, options.split, submission.label, out.issues);
  if (!split) return out;
  ReceiptInputs inputs;
  inputs.split = *split;
  inputs.verify_ground_truth = options.verify_ground_truth;
  inputs.submission_sha256 = checked.sha256;
  inputs.submission_bytes = checked.bytes;
  GraphSet truth;
  if (ground_truth.text) {
    truth = graphs_from_submission(parse_json_strict(*ground_truth.text, ground_truth.label), ground_truth.label);
    inputs.ground_truth_kind = "memory";
    inputs.ground_truth_sha256 = sha256_hex(*ground_truth.text);
  } else {
    truth = load_ground_truth(ground_truth.path, *split, options.limits, options.verify_ground_truth,
                              &inputs.ground_truth_sha256);
    inputs.ground_truth_kind = std::filesystem::is_directory(ground_truth.path) ? "dataset" : "file";
  }
  // An observation ladder's rung tiles (<key>-r<k>) are scored per rung beside the split's.
  GraphSet all_rung = out.graphs;
  std::map<int, GraphSet> rung_preds = take_rung_tiles(truth, all_rung);
  // A submission none of whose keys is a tile of the split is for another split (or
  // another dataset): scoring it would report every tile missing, exit 0, all zeros.
  if (!out.graphs.empty() && !truth.empty() && rung_preds.empty() &&
      std::none_of(out.graphs.begin(), out.graphs.end(), [&](const auto& kv) { return truth.count(kv.first) > 0; })) {
    out.issues.error(
        "submission.keys", submission.label,
        strprintf("tiles of split '%s': none of its %zu keys (e.g. '%s') is one of the split's %zu "
                  "tiles (e.g. '%s'); is --split right, and is this the dataset it was predicted for?",
                  printable_text(*split).c_str(), out.graphs.size(), printable_text(out.graphs.begin()->first).c_str(),
                  truth.size(), printable_text(truth.begin()->first).c_str()));
    return out;
  }
  // Each rung is a whole scoring of the split: their number is bounded, and they share the
  // one --max-seconds budget (a submission of 100 000 rungs would multiply the work).
  if (rung_preds.size() > kMaxScoredRungs) {
    out.issues.error("submission.keys", submission.label,
                     strprintf("at most %zu rungs of an observation ladder (keys <tile>-r<k>), got %zu",
                               kMaxScoredRungs, rung_preds.size()));
    return out;
  }
  const auto start = std::chrono::steady_clock::now();
  const auto budget_left = [&] {
    ScoreOptions left = options.score;
    if (left.max_seconds > 0) {
      const double spent = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      left.max_seconds = std::max(1e-6, options.score.max_seconds - spent);
    }
    return left;
  };
  try {
    out.report = score(truth, all_rung, options.score);
    for (const auto& [rung, preds] : rung_preds) out.rung_reports[rung] = score(truth, preds, budget_left());
    if (!out.rung_reports.empty()) out.report.rungs = rungs_to_json(rung_scores(out.rung_reports, out.report));
  } catch (const SearchWorkExceeded& e) {
    // Beyond a scoring limit, as a file beyond the per-tile limits is (exit 1), though only
    // the ground truth tells.
    out.issues.error("submission.size", e.record(), e.expected());
    return out;
  }
  out.report.ground_truth = ground_truth.label;
  out.report.submission = submission.label;
  out.report.split = *split;
  out.report.ground_truth_verification = inputs.ground_truth_kind == "memory" ? "memory"
                                         : inputs.ground_truth_kind == "file" ? "file"
                                         : options.verify_ground_truth        ? "sha256"
                                                                              : "sizes";
  inputs.verification = out.report.ground_truth_verification;
  out.report.receipt = make_receipt(out.report, inputs, options.limits);
  return out;
}

}  // namespace nsg::metrics

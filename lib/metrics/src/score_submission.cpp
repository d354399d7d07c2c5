#include "nsg/metrics/score_submission.h"

#include <algorithm>

#include "nsg/core/error.h"
#include "nsg/core/json.h"
#include "nsg/core/sha256.h"
#include "nsg/core/strings.h"
#include "nsg/metrics/io.h"
#include "nsg/metrics/receipt.h"
#include "nsg/metrics/submission_input.h"

namespace nsg::metrics {

void SubmissionScoreOptions::validate() const {
  score.validate();
  NSG_CHECK(!split.empty(), ConfigError, "", "split", "a split name");
}

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
  ReceiptInputs inputs;
  inputs.split = options.split;
  inputs.verify_ground_truth = options.verify_ground_truth;
  inputs.submission_sha256 = checked.sha256;
  inputs.submission_bytes = checked.bytes;
  GraphSet truth;
  if (ground_truth.text) {
    truth = graphs_from_submission(parse_json_strict(*ground_truth.text, ground_truth.label), ground_truth.label);
    inputs.ground_truth_kind = "memory";
    inputs.ground_truth_sha256 = sha256_hex(*ground_truth.text);
  } else {
    truth = load_ground_truth(ground_truth.path, options.split, options.limits, options.verify_ground_truth,
                              &inputs.ground_truth_sha256);
    inputs.ground_truth_kind = std::filesystem::is_directory(ground_truth.path) ? "dataset" : "file";
  }
  // A submission none of whose keys is a tile of the split is for another split (or
  // another dataset): scoring it would report every tile missing, exit 0, all zeros.
  if (!out.graphs.empty() && !truth.empty() &&
      std::none_of(out.graphs.begin(), out.graphs.end(), [&](const auto& kv) { return truth.count(kv.first) > 0; })) {
    out.issues.error("submission.keys", submission.label,
                     strprintf("tiles of split '%s': none of its %zu keys (e.g. '%s') is one of the split's %zu "
                               "tiles (e.g. '%s'); is --split right, and is this the dataset it was predicted for?",
                               printable_text(options.split).c_str(), out.graphs.size(),
                               printable_text(out.graphs.begin()->first).c_str(), truth.size(),
                               printable_text(truth.begin()->first).c_str()));
    return out;
  }
  try {
    out.report = score(truth, out.graphs, options.score);
  } catch (const SearchWorkExceeded& e) {
    // Beyond a scoring limit, as a file beyond the per-tile limits is (exit 1), though only
    // the ground truth tells.
    out.issues.error("submission.size", e.record(), e.expected());
    return out;
  }
  out.report.ground_truth = ground_truth.label;
  out.report.submission = submission.label;
  out.report.split = options.split;
  out.report.ground_truth_verification = inputs.ground_truth_kind == "memory" ? "memory"
                                         : inputs.ground_truth_kind == "file" ? "file"
                                         : options.verify_ground_truth        ? "sha256"
                                                                              : "sizes";
  inputs.verification = out.report.ground_truth_verification;
  out.report.receipt = make_receipt(out.report, inputs, options.limits);
  return out;
}

}  // namespace nsg::metrics

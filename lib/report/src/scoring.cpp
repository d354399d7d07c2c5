// The sequence of `nsgraph score`: check the submission (validate's limits, schema and
// structural rules), load the ground truth of the split, score.
#include "internal.h"

#include "nsg/metrics/io.h"
#include "nsg/metrics/submission_input.h"

namespace nsg::report::detail {

ScoredSubmission score_submission(const std::filesystem::path& dataset, const std::string& split,
                                  const std::filesystem::path& submission, const std::filesystem::path& schemas,
                                  int threads) {
  ScoredSubmission out;
  metrics::CheckedSubmission checked = metrics::check_submission_file(submission, schemas);
  if (!checked.issues.empty()) {
    out.issues = std::move(checked.issues);
    return out;
  }
  out.graphs = std::move(checked.graphs);
  metrics::ScoreOptions options;
  options.threads = threads;
  const metrics::GraphSet gt = metrics::load_ground_truth(dataset, split);
  out.report = metrics::score(gt, out.graphs, options);
  out.report.ground_truth = dataset.string();
  out.report.submission = submission.string();
  out.report.split = split;
  return out;
}

}  // namespace nsg::report::detail

// metrics::score_submission, the sequence `nsgraph score`, nsgraph.score and the report
// share: on the golden graphs, where the answers are known.
#include <gtest/gtest.h>

#include "nsg/core/error.h"
#include "nsg/core/files.h"
#include "nsg/metrics/io.h"
#include "nsg/metrics/score_submission.h"
#include "test_support.h"

namespace nsg::metrics {
namespace {

namespace fs = std::filesystem;

const fs::path kGolden = nsg::test::data_dir() / "golden" / "metrics";

SubmissionScoreOptions golden_options() {
  SubmissionScoreOptions o;
  o.schemas_dir = nsg::test::source_dir() / "schemas";
  o.score.threads = 2;
  return o;
}

TEST(ScoreSubmission, GroundTruthAgainstItselfIsPerfect) {
  const ScoreSource gt = ScoreSource::file(kGolden / "gt.json");
  const ScoredSubmission s = score_submission(gt, gt, golden_options());
  ASSERT_TRUE(s.scored()) << s.issues.format();
  const AggregateReport& a = s.report.aggregate;
  EXPECT_EQ(a.n_tiles, 43);
  EXPECT_EQ(a.n_missing_predictions, 0);
  EXPECT_EQ(a.n_extra_predictions, 0);
  for (Metric m : {kApls, kAplsDirected, kF1, kIou, kGeoF1, kTopoF1, kTopoDirectedF1}) {
    ASSERT_TRUE(a.mean[m].has_value()) << m;
    EXPECT_DOUBLE_EQ(*a.mean[m], 1.0) << m;
  }
  EXPECT_DOUBLE_EQ(*a.mean[kChamferPx2], 0.0);
  EXPECT_EQ(s.graphs.size(), 43u);
  // The report names its inputs as given.
  EXPECT_EQ(s.report.ground_truth, (kGolden / "gt.json").string());
  EXPECT_EQ(s.report.submission, (kGolden / "gt.json").string());
  EXPECT_EQ(s.report.split, "test");
}

TEST(ScoreSubmission, GoldenPredictionGivesTheGoldenAggregate) {
  const nlohmann::json expected = read_json_file(kGolden / "expected.json");
  const ScoredSubmission s = score_submission(ScoreSource::file(kGolden / "gt.json"),
                                              ScoreSource::file(kGolden / "pred.json"), golden_options());
  ASSERT_TRUE(s.scored()) << s.issues.format();
  EXPECT_EQ(s.report.aggregate.n_missing_predictions, expected["aggregate"]["n_missing_predictions"].get<int64_t>());
  EXPECT_NEAR(*s.report.aggregate.mean[kApls], expected["aggregate"]["mean"]["apls"].get<double>(), 1e-9);
  // In memory (nsgraph.score's dict arguments) the same documents give the same report.
  const ScoredSubmission m =
      score_submission(ScoreSource::memory(read_file(kGolden / "gt.json"), "<gt>"),
                       ScoreSource::memory(read_file(kGolden / "pred.json"), "<memory>"), golden_options());
  ASSERT_TRUE(m.scored()) << m.issues.format();
  nlohmann::json a = report_to_json(s.report), b = report_to_json(m.report);
  EXPECT_EQ(b["ground_truth"], "<gt>");
  EXPECT_EQ(b["submission"], "<memory>");
  EXPECT_EQ(a["ground_truth_verification"], "file");
  EXPECT_EQ(b["ground_truth_verification"], "memory");
  for (const char* k : {"ground_truth", "submission", "ground_truth_verification"}) a.erase(k), b.erase(k);
  EXPECT_EQ(a, b);
}

TEST(ScoreSubmission, CorruptedSubmissionIsRefusedBeforeTheGroundTruthIsRead) {
  // An edge pointing past the node list: the structural check's issue, nothing scored,
  // and the (absent) ground truth never opened.
  const std::string bad = R"({"schema_version":"1","tiles":{"t":{"nodes":[[1,2],[3,4]],"edges":[[0,5]]}}})";
  const ScoredSubmission s = score_submission(ScoreSource::file(kGolden / "absent.json"),
                                              ScoreSource::memory(bad, "bad.json"), golden_options());
  ASSERT_FALSE(s.scored());
  ASSERT_EQ(s.issues.size(), 1u) << s.issues.format();
  EXPECT_EQ(s.issues.items()[0].check, "submission.indices");
  EXPECT_NE(s.issues.format().find("bad.json:/tiles/t/edges/0/1"), std::string::npos) << s.issues.format();
  EXPECT_TRUE(s.graphs.empty());
  // A readable submission and an absent ground truth: an input error (exit 2), not an issue.
  EXPECT_THROW(score_submission(ScoreSource::file(kGolden / "absent.json"), ScoreSource::file(kGolden / "pred.json"),
                                golden_options()),
               IoError);
}

TEST(ScoreSubmission, OptionsAreValidatedFirst) {
  SubmissionScoreOptions o = golden_options();
  o.score.threads = -1;
  EXPECT_THROW(o.validate(), ConfigError);
  o = golden_options();
  o.split.clear();
  try {
    score_submission(ScoreSource::file(kGolden / "gt.json"), ScoreSource::file(kGolden / "gt.json"), o);
    FAIL() << "an empty split was accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.record(), "split");
  }
}

}  // namespace
}  // namespace nsg::metrics

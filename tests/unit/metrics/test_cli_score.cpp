// `nsgraph score` end to end: exit codes 0/1/2, formats, and the report schema.
#include <gtest/gtest.h>

#include "nsg/metrics/io.h"
#include "nsg/validate/schema.h"
#include "test_support.h"

namespace {

namespace fs = std::filesystem;
using nsg::test::run_nsgraph;

const fs::path kGolden = nsg::test::data_dir() / "golden" / "metrics";
const std::string kSchemas = (nsg::test::source_dir() / "schemas").string();

std::vector<std::string> score_args(const fs::path& submission) {
  return {"score",     "--ground-truth", (kGolden / "gt.json").string(), "--submission", submission.string(),
          "--schemas", kSchemas};
}

TEST(CliScore, ReportIsWrittenAndValidatesAgainstSchema) {
  nsg::test::TempDir dir("score-cli");
  auto args = score_args(kGolden / "pred.json");
  args.insert(args.end(), {"--out", (dir / "report.json").string(), "--threads", "2", "-q"});
  const auto r = run_nsgraph(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json report = nsg::metrics::read_json_file(dir / "report.json");
  EXPECT_EQ(nlohmann::json::parse(r.out), report);
  EXPECT_EQ(report["metrics_version"], "4");
  EXPECT_EQ(report["aggregate"]["n_missing_predictions"], 1);
  const nsg::Issues issues = nsg::validate::validate_against_schema(
      fs::path(kSchemas) / "v1" / "score-report.schema.json", report, "report.json", "report.schema");
  EXPECT_TRUE(issues.empty()) << issues.format();
}

TEST(CliScore, MarkdownTable) {
  auto args = score_args(kGolden / "pred.json");
  args.insert(args.end(), {"--format", "md"});
  const auto r = run_nsgraph(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("| APLS ↑ | APLS dir. ↑"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("| 0.8244 | 0.7434 |"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("| `topo_directed_f1` |"), std::string::npos);
  // The summed Chamfer (m², grows with nodes) is in the table of every metric, not the headline.
  const std::string headline = r.out.substr(0, r.out.find('\n'));
  EXPECT_EQ(headline.find("m²"), std::string::npos) << headline;
  EXPECT_NE(headline.find("mean Chamfer (m)"), std::string::npos) << headline;
  EXPECT_NE(r.out.find("| `chamfer_m2` |"), std::string::npos);
}

TEST(CliScore, CsvHasOneRowPerTile) {
  auto args = score_args(kGolden / "pred.json");
  args.insert(args.end(), {"--format", "csv"});
  const auto r = run_nsgraph(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1 + 43);
  EXPECT_EQ(r.out.rfind("key,apls,", 0), 0u);
}

TEST(CliScore, InvalidSubmissionExits1NamingFileKeyAndPath) {
  nsg::test::TempDir dir("score-cli");
  const fs::path bad = dir / "bad.json";
  nsg::test::write_text(bad, R"({"schema_version":"1","tiles":{"straight-gap":{"nodes":[[1,2],[3,4]],"edges":[[0,5]]},)"
                             R"("curve-gap":{"nodes":[["x",2]],"edges":[]}}})");
  const auto r = run_nsgraph(score_args(bad));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find(bad.string() + ":/tiles/straight-gap/edges/0/1"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("submission.indices"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("/tiles/curve-gap/nodes/0/0"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty());
}

// A submission none of whose keys is a tile of the split (another split's, or look-alike
// keys) is refused by name instead of scored as every tile missing (exit 0, all zeros);
// one matching key is enough to score (the others are extra, as documented).
TEST(CliScore, ASubmissionWithNoKeyOfTheSplitIsRefused) {
  nsg::test::TempDir dir("score-cli-keys");
  const fs::path other = dir / "other.json";
  const std::string tile = R"({"nodes":[[1,2],[30,4]],"edges":[[0,1]]})";
  nsg::test::write_text(other, R"({"schema_version":"1","tiles":{"boston-seaport-train-000001":)" + tile +
                                   R"(,"straight‐gap":)" + tile + "}}");
  const auto r = run_nsgraph(score_args(other));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("submission.keys"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("none of its 2 keys"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("is --split right"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty());
  const fs::path one = dir / "one.json";
  nsg::test::write_text(one, R"({"schema_version":"1","tiles":{"boston-seaport-train-000001":)" + tile +
                                 R"(,"straight-gap":)" + tile + "}}");
  EXPECT_EQ(run_nsgraph(score_args(one)).exit_code, 0);
}

// A submission that is not JSON is an invalid submission (exit 1, as validate --submission
// says); an unreadable file or a bad option is an input error (exit 2).
TEST(CliScore, MalformedSubmissionExits1UnreadableInputExits2) {
  nsg::test::TempDir dir("score-cli");
  const fs::path truncated = dir / "truncated.json";
  nsg::test::write_text(truncated, R"({"schema_version":"1","tiles":{"a":{"nodes":[[1,)");
  auto r = run_nsgraph(score_args(truncated));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find(truncated.string()), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("submission.json"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty());
  r = run_nsgraph(score_args(dir / "absent.json"));
  EXPECT_EQ(r.exit_code, 2);
  auto args = score_args(kGolden / "pred.json");
  args.insert(args.end(), {"--format", "xml"});
  EXPECT_EQ(run_nsgraph(args).exit_code, 2);
}

// A submission beyond the validate limits is refused before any DOM is built: a sparse
// 200 MB file (nothing read: the size check comes first) and a deeply nested one.
TEST(CliScore, OversizedSubmissionIsRefusedWithExit1) {
  nsg::test::TempDir dir("score-cli");
  const fs::path huge = dir / "huge.json";
  nsg::test::write_text(huge, "{");
  fs::resize_file(huge, std::uintmax_t{200} << 20);
  const auto r = run_nsgraph(score_args(huge));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("submission.size"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("200.0 MiB"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty());
}

TEST(CliScore, DeeplyNestedSubmissionIsRefusedWithExit1) {
  nsg::test::TempDir dir("score-cli");
  const fs::path deep = dir / "deep.json";
  nsg::test::write_text(deep, R"({"schema_version":"1","tiles":{"a":{"nodes":)" + std::string(100000, '[') +
                                  std::string(100000, ']') + "}}}");
  const auto r = run_nsgraph(score_args(deep));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("submission.size"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("nesting at most 16 deep"), std::string::npos) << r.err;
}

// The same limits guard a ground truth in the submission format; it is input data, not
// the thing under validation, so a refused one is an input error (exit 2).
TEST(CliScore, OversizedGroundTruthFileExits2) {
  nsg::test::TempDir dir("score-cli");
  const fs::path huge = dir / "gt.json";
  nsg::test::write_text(huge, "{");
  fs::resize_file(huge, std::uintmax_t{200} << 20);
  const auto r = run_nsgraph({"score", "--ground-truth", huge.string(), "--submission",
                              (kGolden / "pred.json").string(), "--schemas", kSchemas});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(huge.string()), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("submission limits"), std::string::npos) << r.err;
}

// A pipe has no size to check up front: it is read within the same byte limit.
TEST(CliScore, SubmissionFromAPipeOrStdin) {
  const std::string exe = nsg::test::nsgraph_exe().string();
  const std::string common = exe + " score -q --ground-truth '" + (kGolden / "gt.json").string() + "' --schemas '" +
                             kSchemas + "' --format csv --submission ";
  const std::string pred = "'" + (kGolden / "pred.json").string() + "'";
  const auto file = run_nsgraph({"score", "-q", "--ground-truth", (kGolden / "gt.json").string(), "--submission",
                                 (kGolden / "pred.json").string(), "--schemas", kSchemas, "--format", "csv"});
  ASSERT_EQ(file.exit_code, 0) << file.err;
  const auto piped = nsg::test::run_program({"/bin/bash", "-c", common + "<(cat " + pred + ")"});
  EXPECT_EQ(piped.exit_code, 0) << piped.err;
  EXPECT_EQ(piped.out, file.out);
  const auto stdin_run = nsg::test::run_program({"/bin/bash", "-c", common + "/dev/stdin < " + pred});
  EXPECT_EQ(stdin_run.exit_code, 0) << stdin_run.err;
  EXPECT_EQ(stdin_run.out, file.out);
  // 129 MiB of spaces after the document: refused once the limit is passed, exit 1.
  const auto big = nsg::test::run_program(
      {"/bin/bash", "-c", common + "<(cat " + pred + "; head -c 135266304 /dev/zero | tr '\\0' ' ')"});
  EXPECT_EQ(big.exit_code, 1) << big.err;
  EXPECT_NE(big.err.find("at most 128 MiB, got a longer stream"), std::string::npos) << big.err;
  const auto raised = nsg::test::run_program(
      {"/bin/bash", "-c",
       common + "<(cat " + pred + "; head -c 135266304 /dev/zero | tr '\\0' ' ') --max-file-mb 200"});
  EXPECT_EQ(raised.exit_code, 0) << raised.err;
  EXPECT_EQ(raised.out, file.out);
}

// score and validate --submission take the one limit flag set: a file refused by one is
// refused by the other, at the default and at a lowered limit alike.
TEST(CliScore, ScoreAndValidateTakeTheSameLimits) {
  nsg::test::TempDir dir("score-limits");
  const fs::path padded = dir / "padded.json";
  nsg::test::write_text(padded, nsg::test::read_text(kGolden / "pred.json") + std::string(3 << 20, ' '));
  const std::vector<std::string> score = {"score",          "-q",
                                          "--ground-truth", (kGolden / "gt.json").string(),
                                          "--submission",   padded.string(),
                                          "--schemas",      kSchemas,
                                          "--format",       "csv"};
  const std::vector<std::string> validate = {"validate", "--submission", padded.string(), "--schemas", kSchemas};
  for (const bool lowered : {false, true}) {
    std::vector<std::string> s = score, v = validate;
    if (lowered)
      for (auto* args : {&s, &v}) args->insert(args->end(), {"--max-file-mb", "2"});
    const auto scored = run_nsgraph(s);
    const auto validated = run_nsgraph(v);
    EXPECT_EQ(scored.exit_code, lowered ? 1 : 0) << scored.err;
    EXPECT_EQ(validated.exit_code, lowered ? 1 : 0) << validated.out << validated.err;
    if (lowered) {
      EXPECT_NE(scored.err.find("at most 2 MiB"), std::string::npos) << scored.err;
      EXPECT_NE(validated.out.find("at most 2 MiB"), std::string::npos) << validated.out;
    }
  }
  for (const char* command : {"score", "validate"}) {
    const auto help = run_nsgraph({command, "--help"});
    EXPECT_NE(help.out.find("--max-file-mb"), std::string::npos) << command;
    EXPECT_NE(help.out.find("per tile at most 5000 nodes, 10000 edges and 100000 px"), std::string::npos) << command;
  }
}

// JSON leaves a repeated key open; keeping the last would let a duplicate swing a score.
TEST(CliScore, DuplicateKeysExit1) {
  nsg::test::TempDir dir("score-cli");
  const fs::path dup = dir / "dup.json";
  nsg::test::write_text(dup, R"({"schema_version":"2","schema_version":"1","tiles":{}})");
  const auto r = run_nsgraph(score_args(dup));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find(dup.string() + ": key \"schema_version\""), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("each key once"), std::string::npos) << r.err;
}

// The whole run's wall-clock budget: beyond it the run stops with exit 2 naming the flag.
TEST(CliScore, MaxSecondsStopsTheRunByName) {
  std::vector<std::string> args = {"score",          "-q",
                                   "--ground-truth", (kGolden / "gt.json").string(),
                                   "--submission",   (kGolden / "pred.json").string(),
                                   "--schemas",      kSchemas,
                                   "--format",       "csv"};
  args.insert(args.end(), {"--max-seconds", "1e-9"});
  auto r = run_nsgraph(args);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--max-seconds"), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");
  args.back() = "0";  // no limit
  r = run_nsgraph(args);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  args.back() = "-1";
  EXPECT_EQ(run_nsgraph(args).exit_code, 2);
}

TEST(CliScore, HelpStatesTheLimits) {
  const auto r = run_nsgraph({"score", "--help"});
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("per tile at most 5000 nodes, 10000 edges and 100000 px"), std::string::npos) << r.out;
}

}  // namespace

// Reproduces every value of tests/data/golden/metrics/expected.json (per tile and
// aggregate) from gt.json and pred.json to 1e-9; null stays null.
#include <gtest/gtest.h>

#include <cmath>

#include "nsg/metrics/io.h"
#include "nsg/metrics/score.h"
#include "test_support.h"

namespace nsg::metrics {
namespace {

const std::filesystem::path kGolden = nsg::test::data_dir() / "golden" / "metrics";

void expect_close(const nlohmann::json& want, const nlohmann::json& got, const std::string& where) {
  if (want.is_null()) {
    EXPECT_TRUE(got.is_null()) << where << ": expected null, got " << got.dump();
    return;
  }
  ASSERT_TRUE(got.is_number()) << where << ": expected " << want.dump() << ", got " << got.dump();
  const double w = want.get<double>(), g = got.get<double>();
  EXPECT_LE(std::abs(w - g), 1e-9 * std::max(1.0, std::abs(w)))
      << where << ": expected " << want.dump() << ", got " << got.dump();
}

// gt.json with the edge classes of metrics v2's per-class recalls, which its submission
// format cannot carry: edge_flags.json, made by geo_topo_v2_reference.py.
GraphSet golden_ground_truth() {
  GraphSet gt = graphs_from_submission(read_json_file(kGolden / "gt.json"), "gt.json");
  const nlohmann::json flags = read_json_file(kGolden / "edge_flags.json").at("tiles");
  for (auto& [key, graph] : gt) graph.edge_flags = flags.at(key).get<std::vector<uint8_t>>();
  return gt;
}

class Golden : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const GraphSet gt = golden_ground_truth();
    const GraphSet pred = graphs_from_submission(read_json_file(kGolden / "pred.json"), "pred.json");
    ScoreOptions options;
    options.threads = 2;
    report_ = new nlohmann::json(report_to_json(score(gt, pred, options)));
    expected_ = new nlohmann::json(read_json_file(kGolden / "expected.json"));
  }
  static void TearDownTestSuite() {
    delete report_;
    delete expected_;
  }
  static nlohmann::json* report_;
  static nlohmann::json* expected_;
};
nlohmann::json* Golden::report_ = nullptr;
nlohmann::json* Golden::expected_ = nullptr;

TEST_F(Golden, SameTileKeys) {
  std::vector<std::string> want, got;
  for (const auto& [k, v] : (*expected_)["tiles"].items()) want.push_back(k);
  for (const auto& [k, v] : (*report_)["tiles"].items()) got.push_back(k);
  EXPECT_EQ(want, got);
}

TEST_F(Golden, EveryTileValueAndCount) {
  for (const auto& [key, tile] : (*expected_)["tiles"].items()) {
    const nlohmann::json& ours = (*report_)["tiles"][key];
    for (const auto& [name, value] : tile.items()) {
      if (name == "counts") {
        for (const auto& [count, n] : value.items()) EXPECT_EQ(n, ours["counts"][count]) << key << " counts." << count;
      } else {
        expect_close(value, ours[name], key + "." + name);
      }
    }
  }
}

TEST_F(Golden, EveryAggregateValue) {
  const nlohmann::json& want = (*expected_)["aggregate"];
  const nlohmann::json& got = (*report_)["aggregate"];
  for (const char* n : {"n_tiles", "n_missing_predictions", "n_extra_predictions"}) EXPECT_EQ(want[n], got[n]) << n;
  for (const char* group : {"mean", "pooled"})
    for (const auto& [name, value] : want[group].items())
      expect_close(value, got[group][name], std::string(group) + "." + name);
  for (const char* group : {"n_defined", "n_undefined", "sums"})
    for (const auto& [name, value] : want[group].items()) EXPECT_EQ(value, got[group][name]) << group << "." << name;
}

TEST_F(Golden, MissingTileListed) {
  EXPECT_EQ((*report_)["missing_tiles"], nlohmann::json::array({"edge-missing-pred"}));
  EXPECT_EQ((*report_)["metrics_version"], "4");
}

TEST_F(Golden, ThreadCountDoesNotChangeTheReport) {
  const GraphSet gt = golden_ground_truth();
  const GraphSet pred = graphs_from_submission(read_json_file(kGolden / "pred.json"), "pred.json");
  ScoreOptions one;
  one.threads = 1;
  EXPECT_EQ(report_to_json(score(gt, pred, one)).dump(), report_->dump());
}

// sda_cases.json (sda_reference.py --cases): tiles where SDA@20 and SDA@50 disagree and
// where the least-distance assignment is not the greedy nearest match.
TEST(GoldenSda, RadiiDisagreeAndTheAssignmentIsNotGreedy) {
  const nlohmann::json cases = read_json_file(kGolden / "sda_cases.json");
  const GraphSet gt = graphs_from_submission(cases.at("gt"), "sda_cases.json gt");
  const GraphSet pred = graphs_from_submission(cases.at("pred"), "sda_cases.json pred");
  const nlohmann::json report = report_to_json(score(gt, pred, ScoreOptions{}));
  size_t radii_differ = 0;
  for (const auto& [key, want] : cases.at("expected").items()) {
    const nlohmann::json& ours = report["tiles"][key];
    for (const auto& [name, value] : want.items()) {
      if (name == "counts") {
        for (const auto& [count, n] : value.items()) EXPECT_EQ(n, ours["counts"][count]) << key << " counts." << count;
      } else {
        expect_close(value, ours[name], key + "." + name);
      }
    }
    radii_differ += want["counts"]["sda20_matched"] != want["counts"]["sda50_matched"];
  }
  EXPECT_EQ(cases.at("expected").size(), 7u);
  EXPECT_GE(radii_differ, 6u);
}

// A graph of change_cases.json: nodes, edges and, for the maps, edge_flags (EdgeFlag bytes).
Graph case_graph(const nlohmann::json& doc) {
  Graph g;
  for (const auto& n : doc.at("nodes")) g.nodes.push_back({n.at(0).get<double>(), n.at(1).get<double>()});
  for (const auto& e : doc.at("edges")) g.edges.push_back({e.at(0).get<int64_t>(), e.at(1).get<int64_t>()});
  if (doc.contains("edge_flags")) g.edge_flags = doc.at("edge_flags").get<std::vector<uint8_t>>();
  return g;
}

// change_cases.json (change_reference.py --write): a lane added, removed, moved, retyped and
// a turn added, each against a prediction that follows the current map, one that copies the
// prior and ones in between; every change metric, the changed/unchanged recalls and counts.
TEST(GoldenChange, EveryCaseAsTheIndependentReferenceScoresIt) {
  const nlohmann::json cases = read_json_file(kGolden / "change_cases.json");
  GraphSet gt, pred;
  for (const auto& [key, tile] : cases.at("tiles").items()) {
    Graph current = case_graph(tile.at("gt"));
    current.prior = std::make_shared<const Graph>(case_graph(tile.at("prior")));
    gt.emplace(key, std::move(current));
    pred.emplace(key, case_graph(tile.at("pred")));
  }
  const nlohmann::json report = report_to_json(score(gt, pred, ScoreOptions{}));
  size_t compared = 0;
  for (const auto& [key, tile] : cases.at("tiles").items()) {
    const nlohmann::json& ours = report["tiles"][key];
    for (const auto& [name, value] : tile.at("expect").items()) {
      if (name == "counts") {
        for (const auto& [count, n] : value.items()) EXPECT_EQ(n, ours["counts"][count]) << key << " counts." << count;
      } else {
        expect_close(value, ours[name], key + "." + name);
        ++compared;
      }
    }
  }
  EXPECT_EQ(cases.at("tiles").size(), 13u);
  EXPECT_GE(compared, 13u * 13u);
  // Copying the prior detects no change and keeps every unchanged sample, on every case.
  for (const auto& [key, tile] : cases.at("tiles").items()) {
    if (key.find("copies-prior") == std::string::npos) continue;
    const nlohmann::json& ours = report["tiles"][key];
    if (!ours["change_recall"].is_null()) EXPECT_EQ(ours["change_recall"], 0.0) << key;
    EXPECT_TRUE(ours["change_precision"].is_null()) << key << ": no change claimed";
    EXPECT_EQ(ours["false_change_rate"], 0.0) << key;
    EXPECT_EQ(ours["unchanged_precision"], 1.0) << key;
  }
}

// A ground truth without a prior (every dataset not generated in map-update mode) has no
// change metric: undefined, never 0.
TEST(GoldenChange, UndefinedWithoutAPrior) {
  const GraphSet gt = golden_ground_truth();
  const GraphSet pred = graphs_from_submission(read_json_file(kGolden / "pred.json"), "pred.json");
  const nlohmann::json report = report_to_json(score(gt, pred, ScoreOptions{}));
  for (const char* name : {"change_recall", "change_precision", "false_change_rate", "unchanged_precision",
                           "geo_recall_changed", "topo_recall_unchanged"}) {
    EXPECT_EQ(report["aggregate"]["n_defined"][name], 0) << name;
  }
  EXPECT_TRUE(report["aggregate"]["pooled"]["change_recall"].is_null());
}

}  // namespace
}  // namespace nsg::metrics

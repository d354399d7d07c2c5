// The worked examples of docs/metrics.md, read from the document itself: every fenced
// ```json block whose object has an "example" member is scored and compared with the
// values it states, so the document and the scorer cannot drift apart.
//
// Block shapes (graphs in the submission shape {"nodes": [[u, v], ...], "edges": [[i, j], ...]}):
//   one tile:   {"example": name, "gt": graph, "pred": graph | null (missing), "expect": {...}},
//               a map-update tile with "prior": graph (both maps' graphs with "edge_flags")
//               "expect" is a subset of the tile's report row (metric names, "counts").
//   a split:    {"example": name, "gt_tiles": {key: graph}, "pred_tiles": {key: graph},
//                "expect_report": {...}}   a subset of the whole JSON report.
// Numbers are printed to 6 decimals (or exactly): a value passes within 5e-7; integers
// (counts) and null (undefined) must match exactly.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "nsg/core/files.h"
#include "nsg/metrics/io.h"
#include "nsg/metrics/measure.h"
#include "nsg/metrics/params.h"
#include "nsg/metrics/score.h"
#include "test_support.h"

namespace nsg::metrics {
namespace {

constexpr double kPrintedTolerance = 5e-7;  // values are printed to 6 decimals

const std::filesystem::path kDoc = nsg::test::source_dir() / "docs" / "metrics.md";

// Every ```json ... ``` block of a Markdown text, with the line it starts on.
struct Block {
  int line = 0;
  std::string text;
};

std::vector<Block> json_blocks(const std::string& markdown) {
  std::vector<Block> blocks;
  std::istringstream in(markdown);
  std::string line;
  int number = 0;
  Block* open = nullptr;
  while (std::getline(in, line)) {
    ++number;
    if (open == nullptr) {
      if (line.rfind("```json", 0) == 0) {
        blocks.push_back({number + 1, ""});
        open = &blocks.back();
      }
    } else if (line.rfind("```", 0) == 0) {
      open = nullptr;
    } else {
      open->text += line + "\n";
    }
  }
  return blocks;
}

struct Example {
  std::string name;
  int line = 0;
  nlohmann::json doc;
};

std::vector<Example> examples() {
  std::vector<Example> out;
  for (const Block& b : json_blocks(nsg::test::read_text(kDoc))) {
    nlohmann::json j = nlohmann::json::parse(b.text, nullptr, /*allow_exceptions=*/false);
    if (j.is_discarded() || !j.is_object() || !j.contains("example")) continue;
    out.push_back({j["example"].get<std::string>(), b.line, std::move(j)});
  }
  return out;
}

// A graph of an example; a map's may carry "edge_flags" (EdgeFlag bytes, the submission
// format has none).
Graph graph_of(const nlohmann::json& g) {
  nlohmann::json tile = g;
  tile.erase("edge_flags");
  const nlohmann::json doc = {{"schema_version", "1"}, {"tiles", {{"t", tile}}}};
  Graph out = graphs_from_submission(doc, "docs/metrics.md").at("t");
  if (g.contains("edge_flags")) out.edge_flags = g["edge_flags"].get<std::vector<uint8_t>>();
  return out;
}

GraphSet graphs_of(const nlohmann::json& tiles) {
  const nlohmann::json doc = {{"schema_version", "1"}, {"tiles", tiles}};
  return graphs_from_submission(doc, "docs/metrics.md");
}

// `want` must be contained in `got`: objects member by member, arrays element by element,
// numbers within the printed precision (exactly for integers), everything else equal.
void expect_subset(const nlohmann::json& want, const nlohmann::json& got, const std::string& where) {
  if (want.is_object()) {
    ASSERT_TRUE(got.is_object()) << where << ": expected an object, got " << got.dump();
    for (const auto& [name, value] : want.items()) {
      ASSERT_TRUE(got.contains(name)) << where << "." << name << ": not in the report";
      expect_subset(value, got[name], where + "." + name);
    }
  } else if (want.is_array()) {
    ASSERT_TRUE(got.is_array()) << where << ": expected an array, got " << got.dump();
    ASSERT_EQ(want.size(), got.size()) << where << ": expected " << want.dump() << ", got " << got.dump();
    for (size_t k = 0; k < want.size(); ++k) expect_subset(want[k], got[k], where + "[" + std::to_string(k) + "]");
  } else if (want.is_number_integer() && got.is_number_integer()) {
    EXPECT_EQ(want.get<int64_t>(), got.get<int64_t>()) << where;
  } else if (want.is_number()) {
    ASSERT_TRUE(got.is_number()) << where << ": expected " << want.dump() << ", got " << got.dump();
    EXPECT_LE(std::abs(want.get<double>() - got.get<double>()), kPrintedTolerance)
        << where << ": the doc says " << want.dump() << ", the scorer gives " << got.dump();
  } else {
    EXPECT_EQ(want, got) << where;
  }
}

void check_example(const Example& e) {
  const std::string where = "docs/metrics.md:" + std::to_string(e.line) + " " + e.name;
  const MetricParams params;  // the examples use the benchmark's defaults
  if (e.doc.contains("gt")) {
    ASSERT_TRUE(e.doc.contains("pred") && e.doc.contains("expect")) << where << ": needs pred and expect";
    Graph gt = graph_of(e.doc["gt"]);
    if (e.doc.contains("prior")) gt.prior = std::make_shared<const Graph>(graph_of(e.doc["prior"]));
    const bool missing = e.doc["pred"].is_null();
    const Graph pred = missing ? Graph{} : graph_of(e.doc["pred"]);
    const TileMeasurement t = measure(e.name, gt, missing ? nullptr : &pred, params);
    expect_subset(e.doc["expect"], measurement_to_json(t), where);
  } else {
    ASSERT_TRUE(e.doc.contains("gt_tiles") && e.doc.contains("pred_tiles") && e.doc.contains("expect_report"))
        << where << ": needs gt_tiles, pred_tiles and expect_report";
    ScoreOptions options;
    options.params = params;
    const ScoreReport report = score(graphs_of(e.doc["gt_tiles"]), graphs_of(e.doc["pred_tiles"]), options);
    expect_subset(e.doc["expect_report"], report_to_json(report), where);
  }
}

TEST(MetricsDoc, StatesTheVersionTheScorerReports) {
  const std::string doc = nsg::test::read_text(kDoc);
  EXPECT_NE(doc.find("metrics_version: \"" + std::string(kMetricsVersion) + "\""), std::string::npos)
      << "docs/metrics.md must name the metrics_version the scorer writes";
}

TEST(MetricsDoc, HasAWorkedExampleForEveryRule) {
  std::set<std::string> names;
  for (const Example& e : examples()) {
    EXPECT_TRUE(names.insert(e.name).second) << "example name used twice: " << e.name;
  }
  for (const char* rule : {"cleaning", "zero-length-edge", "apls-gap", "apls-detour", "apls-offset", "apls-directed",
                           "direction", "direction-two-way", "f1-iou", "chamfer", "geo-topo", "empty-both",
                           "missing-prediction", "hallucination", "aggregation"})
    EXPECT_EQ(names.count(rule), 1u) << "docs/metrics.md has no worked example '" << rule << "'";
}

TEST(MetricsDoc, EveryWorkedExampleScoresAsStated) {
  const std::vector<Example> all = examples();
  ASSERT_FALSE(all.empty()) << "no worked examples found in " << kDoc;
  for (const Example& e : all) {
    SCOPED_TRACE(e.name);
    check_example(e);
  }
}

}  // namespace
}  // namespace nsg::metrics

namespace nsg::metrics {
namespace {

// The metric table (measure.h metric_info) is what the score-report schema's four metric
// lists say: per-tile values, the aggregate's mean, n_defined and n_undefined each require
// and declare exactly the metric names, in Metric order. And docs/metrics.md names each.
TEST(MetricTable, ScoreReportSchemaAndDocsListEveryMetricInOrder) {
  std::vector<std::string> names;
  for (int m = 0; m < kMetricCount; ++m) {
    const MetricInfo& info = metric_info(m);
    EXPECT_EQ(std::string(info.name), metric_name(m));
    EXPECT_GT(std::string(info.description).size(), 5u) << info.name;
    // Only the distances (the only metrics with a unit) and the false-change rate grow with error.
    EXPECT_EQ(info.lower_is_better, std::string(info.unit) != "" || std::string(info.name) == "false_change_rate")
        << info.name;
    names.push_back(info.name);
  }
  const nlohmann::json schema =
      nlohmann::json::parse(nsg::read_file(nsg::test::source_dir() / "schemas/v1/score-report.schema.json"));
  const nlohmann::json& aggregate = schema["properties"]["aggregate"]["properties"];
  for (const nlohmann::json* part :
       {&schema["definitions"]["tile"], &aggregate["mean"], &aggregate["n_defined"], &aggregate["n_undefined"]}) {
    std::vector<std::string> required = part->at("required").get<std::vector<std::string>>(), declared;
    for (const auto& [key, value] : part->at("properties").items()) declared.push_back(key);
    required.erase(std::remove(required.begin(), required.end(), "key"), required.end());
    declared.erase(std::remove(declared.begin(), declared.end(), "key"), declared.end());
    declared.erase(std::remove(declared.begin(), declared.end(), "counts"), declared.end());
    required.erase(std::remove(required.begin(), required.end(), "counts"), required.end());
    EXPECT_EQ(required, names) << "schemas/v1/score-report.schema.json: a metric list differs from metric_info";
    std::sort(declared.begin(), declared.end());
    std::vector<std::string> sorted = names;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(declared, sorted);
  }
  const std::string doc = nsg::read_file(kDoc);
  for (const std::string& n : names) EXPECT_NE(doc.find("`" + n + "`"), std::string::npos) << n;
}

}  // namespace
}  // namespace nsg::metrics

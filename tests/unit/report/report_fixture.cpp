#include "report_fixture.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "generate_fixture.h"
#include "nsg/core/files.h"
#include "nsg/io/dataset.h"
#include "nsg/metrics/io.h"
#include "test_support.h"

namespace nsg::test {

namespace fs = std::filesystem;

namespace {

nlohmann::json submission_of(const metrics::Graph& g, bool reverse) {
  nlohmann::json nodes = nlohmann::json::array(), edges = nlohmann::json::array();
  for (const auto& n : g.nodes) nodes.push_back({n.u, n.v});
  for (const auto& e : g.edges) edges.push_back(reverse ? nlohmann::json{e[1], e[0]} : nlohmann::json{e[0], e[1]});
  return {{"nodes", nodes}, {"edges", edges}};
}

template <class F>
nlohmann::json test_tiles(F&& per_tile) {
  nlohmann::json sub = {{"schema_version", "1"}, {"tiles", nlohmann::json::object()}};
  const io::Dataset d = io::Dataset::open(e2e_dataset());
  d.for_each_tile("test", [&](const io::DatasetTile& t) {
    const metrics::Graph g = metrics::tile_graph(t);
    per_tile(t.key, g, sub["tiles"]);
    return true;
  });
  return sub;
}

}  // namespace

PerturbedSubmission perturbed_submission(const fs::path& dir) {
  PerturbedSubmission p;
  const nlohmann::json sub = test_tiles([&](const std::string& key, const metrics::Graph& g, nlohmann::json& tiles) {
    if (p.dropped.empty() && !g.edges.empty()) {
      p.dropped = key;
      return;
    }
    const bool reverse = p.reversed.empty() && g.edges.size() >= 3;
    if (reverse) {
      p.reversed = key;
      p.reversed_edges = static_cast<int>(g.edges.size());
    }
    tiles[key] = submission_of(g, reverse);
  });
  EXPECT_FALSE(p.dropped.empty());
  EXPECT_FALSE(p.reversed.empty());
  p.file = dir / "perturbed.json";
  write_text(p.file, sub.dump());
  return p;
}

fs::path exact_submission(const fs::path& dir) {
  const nlohmann::json sub = test_tiles([](const std::string& key, const metrics::Graph& g, nlohmann::json& tiles) {
    tiles[key] = submission_of(g, false);
  });
  write_text(dir / "exact.json", sub.dump());
  return dir / "exact.json";
}

fs::path ladder_submission(const fs::path& dir) {
  nlohmann::json tiles = nlohmann::json::object();
  io::Dataset::open(e2e_ladder_dataset()).for_each_tile("test", [&](const io::DatasetTile& t) {
    const nlohmann::json exact = submission_of(metrics::tile_graph(t), false);
    tiles[t.key] = tiles[t.key + "-r2"] = tiles[t.key + "-r4"] = exact;
    tiles[t.key + "-r1"] = {{"nodes", nlohmann::json::array()}, {"edges", nlohmann::json::array()}};
    return true;
  });
  write_text(dir / "ladder-sub.json", nlohmann::json{{"schema_version", "1"}, {"tiles", tiles}}.dump());
  return dir / "ladder-sub.json";
}

fs::path leaderboard_reports(const fs::path& dir) {
  const fs::path reports = dir / "reports";
  fs::create_directories(reports);
  const fs::path empty = dir / "empty-submission.json";
  write_text(empty, test_tiles([](const std::string& key, const metrics::Graph&, nlohmann::json& tiles) {
                      tiles[key] = {{"nodes", nlohmann::json::array()}, {"edges", nlohmann::json::array()}};
                    }).dump());
  const std::vector<std::pair<std::string, fs::path>> subs = {
      {"exact", exact_submission(dir)}, {"perturbed", perturbed_submission(dir).file}, {"empty", empty}};
  for (const auto& [name, file] : subs) {
    const CommandResult r =
        run_nsgraph({"score", "--quiet", "--ground-truth", e2e_dataset().string(), "--submission", file.string(),
                     "--format", "csv", "--out", (reports / (name + ".json")).string()});
    EXPECT_EQ(r.exit_code, 0) << r.err;
  }
  return reports;
}

std::vector<std::string> leaderboard_order(const nlohmann::json& board, const std::string& column,
                                           const std::string& dir) {
  std::string better;
  for (const auto& c : board["columns"])
    if (c["name"] == column) better = c["better"];
  const bool ascending = dir.empty() ? better == "lower" : dir == "asc";
  std::vector<nlohmann::json> entries(board["entries"].begin(), board["entries"].end());
  std::stable_sort(entries.begin(), entries.end(), [&](const nlohmann::json& a, const nlohmann::json& b) {
    const nlohmann::json &x = a["values"][column], &y = b["values"][column];
    if (x.is_null() != y.is_null()) return y.is_null();
    if (!x.is_null() && x.get<double>() != y.get<double>())
      return ascending ? x.get<double>() < y.get<double>() : x.get<double>() > y.get<double>();
    return a["name"].get<std::string>() < b["name"].get<std::string>();
  });
  std::vector<std::string> names;
  for (const auto& e : entries) names.push_back(e["name"]);
  return names;
}

nlohmann::json read_data_script(const fs::path& file) {
  const std::string text = read_file(file);
  const size_t open = text.find(", JSON.parse('");
  const size_t close = text.rfind("'));");
  EXPECT_EQ(text.rfind("NSG.receive(", 0), 0u) << file;
  if (open == std::string::npos || close == std::string::npos) return nullptr;
  std::string json;  // the string literal's content: \\ and \' are its only escapes
  for (size_t i = open + 14; i < close; ++i) {
    if (text[i] == '\\') ++i;
    json += text[i];
  }
  return nlohmann::json::parse(json);
}

}  // namespace nsg::test

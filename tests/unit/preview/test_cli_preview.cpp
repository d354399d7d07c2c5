// `nsgraph preview` end to end: files written, PNG sizes, deterministic bytes, options.
#include <gtest/gtest.h>

#include "nsg/core/files.h"
#include "preview_test_util.h"
#include "test_support.h"

namespace nsg::test {
namespace {

namespace fs = std::filesystem;

// Width and height from a PNG's IHDR chunk.
std::array<uint32_t, 2> png_size(const fs::path& file) {
  const std::string b = read_file(file);
  EXPECT_EQ(b.substr(1, 3), "PNG");
  auto be32 = [&](size_t o) {
    return (uint32_t(uint8_t(b[o])) << 24) | (uint32_t(uint8_t(b[o + 1])) << 16) | (uint32_t(uint8_t(b[o + 2])) << 8) |
           uint32_t(uint8_t(b[o + 3]));
  };
  return {be32(16), be32(20)};
}

TEST(CliPreview, ShardMosaics) {
  TempDir a("preview_a"), b("preview_b");
  const std::string ds = e2e_dataset().string();
  CommandResult r = run_nsgraph({"preview", "--quiet", ds, "--out", a.path().string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* name : {"train-000000", "train-000001", "test-000000", "test-000001", "test-000002"})
    EXPECT_TRUE(fs::exists(a / (std::string(name) + ".png"))) << name;
  EXPECT_EQ(png_size(a / "test-000000.png")[0], 2u * 12 + 4 * 484 + 3 * 12);
  EXPECT_EQ(png_size(a / "test-000002.png")[0], 2u * 12 + 2 * 484 + 12);
  // Same bytes on a second run; --split/--shard/--max-tiles narrow it down.
  r = run_nsgraph(
      {"preview", "--quiet", ds, "--out", b.path().string(), "--split", "test", "--shard", "1", "--max-tiles", "3"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(b.path())) files.push_back(e.path().filename().string());
  EXPECT_EQ(files, std::vector<std::string>{"test-000001.png"});
  EXPECT_EQ(png_size(b / "test-000001.png")[0], 2u * 12 + 3 * 484 + 2 * 12);
  r = run_nsgraph({"preview", "--quiet", ds, "--out", b.path().string(), "--shard", "0"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(read_file(a / "test-000000.png"), read_file(b / "test-000000.png"));
}

TEST(CliPreview, OverviewAndSubmission) {
  TempDir out("preview_o");
  const fs::path ds = e2e_dataset();
  CommandResult r = run_nsgraph({"preview", "--quiet", ds.string(), "--out", out.path().string(), "--overview"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(png_size(out / "overview-boston-seaport.png")[0], 16u + 1265 + 16 + 260 + 16);

  // A submission equal to the GT except one tile left out (scored as empty: APLS 0).
  nlohmann::json sub = {{"schema_version", "1"}, {"tiles", nlohmann::json::object()}};
  const io::Dataset d = io::Dataset::open(ds);
  std::string dropped;
  d.for_each_tile("test", [&](const io::DatasetTile& t) {
    const metrics::Graph g = tile_graph(t);
    if (dropped.empty() && !g.edges.empty()) {
      dropped = t.key;
      return true;
    }
    nlohmann::json nodes = nlohmann::json::array(), edges = nlohmann::json::array();
    for (const auto& n : g.nodes) nodes.push_back({n.u, n.v});
    for (const auto& e : g.edges) edges.push_back({e[0], e[1]});
    sub["tiles"][t.key] = {{"nodes", nodes}, {"edges", edges}};
    return true;
  });
  write_text(out / "sub.json", sub.dump());
  r = run_nsgraph({"preview", "--quiet", ds.string(), "--out", out.path().string(), "--split", "test", "--submission",
                   (out / "sub.json").string(), "--sort", "apls", "--max-tiles", "5"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(png_size(out / "submission-test.png")[0], 2u * 12 + 5 * 484 + 4 * 12);
  // Without --split: the split the keys are tiles of (all splits were scored, the train
  // tiles shown as the worst); keys of no split or of several are refused by name.
  fs::remove(out / "submission-test.png");
  r = run_nsgraph({"preview", ds.string(), "--out", out.path().string(), "--submission", (out / "sub.json").string(),
                   "--sort", "apls", "--max-tiles", "5"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("split 'test' (the split the submission's keys are tiles of)"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(out / "submission-test.png"));
  const int64_t test_tiles = d.manifest().counts.test.tiles;
  EXPECT_NE(r.err.find(std::to_string(test_tiles) + " tile(s) scored"), std::string::npos) << r.err;
  nlohmann::json elsewhere = sub, mixed = sub;
  elsewhere["tiles"] = {{"nowhere-000000", sub["tiles"].begin().value()}};
  d.for_each_tile("train", [&](const io::DatasetTile& t) {
    mixed["tiles"][t.key] = sub["tiles"].begin().value();
    return false;
  });
  write_text(out / "elsewhere.json", elsewhere.dump());
  write_text(out / "mixed.json", mixed.dump());
  r = run_nsgraph(
      {"preview", ds.string(), "--out", out.path().string(), "--submission", (out / "elsewhere.json").string()});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("none of its 1 keys is"), std::string::npos) << r.err;
  r = run_nsgraph(
      {"preview", ds.string(), "--out", out.path().string(), "--submission", (out / "mixed.json").string()});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("give --split"), std::string::npos) << r.err;

  r = run_nsgraph({"preview", ds.string(), "--out", out.path().string(), "--submission", (out / "sub.json").string(),
                   "--sort", "nonsense"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--sort"), std::string::npos) << r.err;
  // A structurally broken submission is a data error naming the file, not a crash.
  write_text(out / "bad.json", R"({"schema_version": "1", "tiles": {"boston-seaport-test-000000":
      {"nodes": [[1, 2]], "edges": [[0, 5]]}}})");
  r = run_nsgraph({"preview", ds.string(), "--out", out.path().string(), "--submission", (out / "bad.json").string()});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("bad.json"), std::string::npos) << r.err;
  r = run_nsgraph({"preview", ds.string(), "--out", out.path().string(), "--shard", "7"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--shard"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace nsg::test

// The report of an observation-ladder dataset (generate --ladder): every split tile's data
// file lists its rung tiles, whose layer images are written beside its own, and with a
// submission each rung's prediction is marked and scored against the same ground truth.
// Known answers: the exact graph at rungs 2, 4 and "all" (APLS 1, nothing missed) and an
// empty graph at rung 1 (APLS 0, every ground-truth edge missed).
#include <gtest/gtest.h>

#include "generate_fixture.h"
#include "nsg/core/files.h"
#include "nsg/io/dataset.h"
#include "nsg/io/tile_meta.h"
#include "nsg/metrics/io.h"
#include "nsg/preview/preview.h"
#include "report_fixture.h"
#include "test_support.h"

namespace nsg::test {
namespace {

namespace fs = std::filesystem;

TEST(Report, LadderTileViewHasEveryRungMarkedAndScored) {
  TempDir dir("report_ladder_tiles");
  const fs::path ds = e2e_ladder_dataset();
  const fs::path out = dir / "report";
  const CommandResult r =
      run_nsgraph({"report", "--quiet", "--dataset", ds.string(), "--submission",
                   ladder_submission(dir.path()).string(), "--split", "test", "--out", out.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const io::Dataset dataset = io::Dataset::open(ds);
  ASSERT_EQ(dataset.rungs(), (std::vector<int>{1, 2, 4}));
  // Rung tiles are views of split tiles, not rows of the per-tile table.
  EXPECT_EQ(read_data_script(out / "data/tiles.js")["keys"].size(), dataset.tile_count("test"));

  std::map<std::string, io::TileMeta> rung_meta;
  dataset.for_each_rung_tile("test", 0, [&](const io::DatasetTile& t) {
    rung_meta[t.key] = t.meta();
    return true;
  });
  ASSERT_EQ(rung_meta.size(), 3 * dataset.tile_count("test"));
  int64_t gt_edges_seen = 0;
  dataset.for_each_tile("test", [&](const io::DatasetTile& tile) {
    const nlohmann::json doc = read_data_script(out / "data/tile" / (tile.key + ".js"));
    const size_t gt_edges = metrics::tile_graph(tile).edges.size();
    gt_edges_seen += static_cast<int64_t>(gt_edges);
    if (gt_edges) {
      EXPECT_EQ(doc["metrics"]["apls"], 1.0) << tile.key;
    }
    EXPECT_EQ(doc["rungs"].size(), 3u) << tile.key;
    if (doc["rungs"].size() != 3u) return false;
    const int want[] = {1, 2, 4};
    for (size_t i = 0; i < 3; ++i) {
      const nlohmann::json& e = doc["rungs"][i];
      const std::string key = tile.key + "-r" + std::to_string(want[i]);
      EXPECT_EQ(e["rung"], want[i]);
      EXPECT_EQ(e["key"], key);
      const io::TileMeta& m = rung_meta.at(key);
      EXPECT_EQ(e["scenes"], m.scenes) << key;
      EXPECT_EQ(e["scenes_seen"], m.ladder->scenes_seen) << key;
      EXPECT_NEAR(e["coverage_lidar"].get<double>(), m.coverage_lidar, 1e-6) << key;
      for (const char* layer : preview::kTileLayerNames)
        EXPECT_TRUE(fs::is_regular_file(out / "img" / (key + "." + layer + ".png"))) << key << " " << layer;
      // Rung 1 predicted nothing: every ground-truth edge missed. Rungs 2 and 4: exact.
      const bool empty = want[i] == 1;
      EXPECT_EQ(e["pred"]["edges"].size(), empty ? 0u : doc["pred"]["edges"].size()) << key;
      EXPECT_EQ(e["marks"]["missed_gt"], empty ? doc["gt"]["edges"].size() : 0u) << key;
      EXPECT_EQ(e["missed"].size(), doc["gt"]["edges"].size()) << key;
      if (gt_edges) {
        EXPECT_EQ(e["metrics"]["apls"], empty ? 0.0 : 1.0) << key;
      }
    }
    return true;
  });
  EXPECT_GT(gt_edges_seen, 0);

  // Without a submission the rungs are there with what they saw, nothing predicted.
  const fs::path plain = dir / "plain";
  ASSERT_EQ(run_nsgraph({"report", "--quiet", "--dataset", ds.string(), "--split", "test", "--out", plain.string()})
                .exit_code,
            0);
  const std::string first = rung_meta.begin()->second.ladder->base_key;
  const nlohmann::json doc = read_data_script(plain / "data/tile" / (first + ".js"));
  ASSERT_EQ(doc["rungs"].size(), 3u);
  EXPECT_FALSE(doc["rungs"][0].contains("pred"));
  EXPECT_FALSE(doc["rungs"][0].contains("metrics"));
  // A report of a rung itself (split test-r1) has the rung's tiles as its tiles, no rungs of rungs.
  const fs::path r1 = dir / "r1";
  ASSERT_EQ(run_nsgraph({"report", "--quiet", "--dataset", ds.string(), "--split", "test-r1", "--out", r1.string()})
                .exit_code,
            0);
  const nlohmann::json r1_doc = read_data_script(r1 / "data/tile" / (first + "-r1.js"));
  EXPECT_FALSE(r1_doc.contains("rungs"));
}

// The real key frame's ladder (one scene: every rung is that scene): each tile view lists its
// three rungs with that scene, and their images are written.
TEST(Report, TheRealKeyFramesRungsAreInItsTileViews) {
  TempDir dir("report_ladder_real");
  ASSERT_EQ(run_nsgraph(real_keyframe_ladder_args(dir / "dataset")).exit_code, 0);
  const fs::path out = dir / "report";
  const CommandResult r = run_nsgraph(
      {"report", "--quiet", "--dataset", (dir / "dataset").string(), "--split", "test", "--out", out.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  size_t tiles = 0;
  io::Dataset::open(dir / "dataset").for_each_tile("test", [&](const io::DatasetTile& tile) {
    const nlohmann::json doc = read_data_script(out / "data/tile" / (tile.key + ".js"));
    EXPECT_EQ(doc["rungs"].size(), 3u) << tile.key;
    for (const nlohmann::json& e : doc["rungs"]) {
      EXPECT_EQ(e["scenes"], nlohmann::json::array({"scene-0061"})) << tile.key;
      EXPECT_TRUE(fs::is_regular_file(out / "img" / (e["key"].get<std::string>() + ".lidar.png"))) << tile.key;
    }
    ++tiles;
    return true;
  });
  EXPECT_GT(tiles, 0u);
}

}  // namespace
}  // namespace nsg::test

// The tile baseline cut into frames: overlapping tiles predict a lane once, a lane crossing
// from one tile into the next is one centerline, links where chains meet; and `predict
// --frames` end to end with the committed e2e model.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "frames_export_fixture.h"
#include "generate_fixture.h"
#include "nsg/core/error.h"
#include "nsg/frames/from_tiles.h"
#include "test_support.h"

namespace nsg::frames {
namespace {

using nlohmann::json;

// A tile of 51.2 m with its west/south corner at (x0, y0) and a graph of map points.
TilePrediction tile(const std::string& key, double x0, double y0, const std::vector<std::pair<double, double>>& pts,
                    const std::vector<std::array<int64_t, 2>>& edges) {
  TilePrediction t;
  t.key = key;
  t.location = "here";
  t.bounds_m = {x0, y0, x0 + 51.2, y0 + 51.2};
  for (const auto& [x, y] : pts) t.graph.nodes.push_back({(x - x0) / 0.2 - 0.5, (y0 + 51.2 - y) / 0.2 - 0.5});
  t.graph.edges = edges;
  return t;
}

std::vector<std::array<int64_t, 2>> chain_edges(size_t n) {
  std::vector<std::array<int64_t, 2>> e;
  for (size_t i = 1; i < n; ++i) e.push_back({static_cast<int64_t>(i - 1), static_cast<int64_t>(i)});
  return e;
}

ExportFrames one_frame(double x, double y) {
  ExportFrames ex;
  ex.frames.push_back({"tok", "here", geometry::Rigid3::from_pose({x, y, 0.0}, geometry::Quaternion{})});
  return ex;
}

TEST(FromTiles, OverlappingTilesPredictALaneOnceAndJoinAcrossTheirBorder) {
  // One eastbound lane at y = 100 from x = 50 to 141.2; tile A covers x 50–101.2, tile B
  // 90–141.2, both predicting it where they see it.
  std::vector<std::pair<double, double>> a, b;
  for (double x = 50; x <= 101.2 + 1e-9; x += 2) a.emplace_back(std::min(x, 101.2), 100.0);
  a.emplace_back(101.2, 100.0);
  for (double x = 90; x <= 141.2 + 1e-9; x += 2) b.emplace_back(x, 100.0);
  b.emplace_back(141.2, 100.0);
  const std::vector<TilePrediction> tiles = {tile("A", 50, 75, a, chain_edges(a.size())),
                                             tile("B", 90, 75, b, chain_edges(b.size()))};
  const json r = tiles_to_frame_results(tiles, one_frame(100, 100), 0.2, "test");
  const json& lanes = r["results"]["tok"]["predictions"]["lane_centerline"];
  ASSERT_EQ(lanes.size(), 1u) << r.dump();
  const json& p = lanes[0]["points"];
  ASSERT_EQ(p.size(), 11u);
  EXPECT_NEAR(p[0][0].get<double>(), -50.0, 1e-3);
  EXPECT_NEAR(p[10][0].get<double>(), 41.2, 1e-3);
  for (const json& q : p) EXPECT_NEAR(q[1].get<double>(), 0.0, 1e-3);
  EXPECT_EQ(lanes[0]["confidence"], 1.0);
  EXPECT_EQ(r["results"]["tok"]["predictions"]["topology_lclc"], json::array({json::array({0.0})}));
}

TEST(FromTiles, ChainsBreakAtAForkAndLinkWhereTheyMeet) {
  // A → fork at (100, 100) → two branches; one tile, edge scores averaged per chain.
  TilePrediction t =
      tile("A", 75, 75, {{80, 100}, {90, 100}, {100, 100}, {110, 105}, {110, 95}}, {{0, 1}, {1, 2}, {2, 3}, {2, 4}});
  t.graph.edge_scores = {0.8, 0.6, 0.9, 0.5};
  const json r = tiles_to_frame_results({t}, one_frame(100, 100), 0.2, "test");
  const json& pred = r["results"]["tok"]["predictions"];
  ASSERT_EQ(pred["lane_centerline"].size(), 3u) << r.dump();
  EXPECT_NEAR(pred["lane_centerline"][0]["confidence"].get<double>(), 0.7, 1e-12);
  const json want =
      json::array({json::array({0.0, 1.0, 1.0}), json::array({0.0, 0.0, 0.0}), json::array({0.0, 0.0, 0.0})});
  EXPECT_EQ(pred["topology_lclc"], want);
}

TEST(FromTiles, PredictFramesWritesResultsThatScoreFrames) {
  test::TempDir tmp("predict-frames");
  const auto dataset = test::e2e_dataset();
  ASSERT_EQ(test::run_nsgraph({"frames", "--quiet", "--dataset", dataset.string(), "--out", (tmp / "frames").string(),
                               "--overlap", "keep"})
                .exit_code,
            0);
  const test::CommandResult p = test::run_nsgraph(
      {"predict", "--quiet", "--model", (test::data_dir() / "golden/model/b1-e2e-trees2.yml.gz").string(), "--dataset",
       dataset.string(), "--split", "test", "--frames", (tmp / "frames").string(), "--out",
       (tmp / "results.json").string()});
  ASSERT_EQ(p.exit_code, 0) << p.err;
  const json results = test::read_json(tmp / "results.json");
  const json manifest = test::read_json(tmp / "frames/manifest.json");
  EXPECT_EQ(results["results"].size(), manifest["counts"]["frames"]["test"].get<size_t>());
  const test::CommandResult s =
      test::run_nsgraph({"score", "--quiet", "--frames", "--ground-truth", (tmp / "frames").string(), "--submission",
                         (tmp / "results.json").string()});
  ASSERT_EQ(s.exit_code, 0) << s.err;
  const json report = json::parse(s.out);
  EXPECT_EQ(report["counts"]["missing_frames"], 0);
  EXPECT_GT(report["DET_l"].get<double>(), 0.0);
  EXPECT_LE(report["DET_l"].get<double>(), 1.0);
  // An export of another dataset is refused by name.
  json other = manifest;
  other["source"]["dataset_manifest_sha256"] = std::string(64, '0');
  test::write_text(tmp / "frames/manifest.json", other.dump());
  const test::CommandResult refused = test::run_nsgraph(
      {"predict", "--quiet", "--model", (test::data_dir() / "golden/model/b1-e2e-trees2.yml.gz").string(), "--dataset",
       dataset.string(), "--frames", (tmp / "frames").string(), "--out", (tmp / "r2.json").string()});
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_NE(refused.err.find("dataset_manifest_sha256"), std::string::npos) << refused.err;
}

// A record without its pose, a manifest without its window: a ParseError naming the file and
// the field (these were json::out_of_range, exit 3), and `predict --frames` refuses the export
// (exit 2) before the model runs.
TEST(FromTiles, AnExportWithoutAPoseOrAWindowIsRefusedByName) {
  test::TempDir tmp("predict-frames-bad");
  json record = test::frame_record_json();
  record.erase("pose");
  test::write_one_record_export(tmp / "no-pose", record);
  try {
    read_export_frames(tmp / "no-pose", "test");
    ADD_FAILURE() << "a record without its pose was read";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), (tmp / "no-pose" / test::kFixtureRecordPath).string());
    EXPECT_EQ(e.record(), "/pose");
  }
  json manifest = test::write_one_record_export(tmp / "no-window");
  manifest["config"].erase("window");
  test::write_text(tmp / "no-window/manifest.json", manifest.dump());
  try {
    read_export_frames(tmp / "no-window", "test");
    ADD_FAILURE() << "a manifest without its window was read";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), (tmp / "no-window/manifest.json").string());
    EXPECT_EQ(e.record(), "/config/window");
  }
  test::write_one_record_export(tmp / "ok");
  const ExportFrames ok = read_export_frames(tmp / "ok", "test");
  ASSERT_EQ(ok.frames.size(), 1u);
  EXPECT_EQ(ok.frames[0].location, "boston-seaport");
  EXPECT_EQ(ok.frames[0].global_from_ego.translation.x(), 600.0);
  EXPECT_EQ(ok.window.y_max_m, 25.0);
  for (const char* name : {"no-pose", "no-window"}) {
    const test::CommandResult p = test::run_nsgraph(
        {"predict", "--quiet", "--model", (test::data_dir() / "golden/model/b1-e2e-trees2.yml.gz").string(),
         "--dataset", test::e2e_dataset().string(), "--split", "test", "--frames", (tmp / name).string(), "--out",
         (tmp / name / "results.json").string()});
    EXPECT_EQ(p.exit_code, 2) << p.err;
    EXPECT_NE(p.err.find(std::string(name) == "no-pose" ? "/pose" : "/config/window"), std::string::npos) << p.err;
    EXPECT_FALSE(std::filesystem::exists(tmp / name / "results.json"));
  }
}

}  // namespace
}  // namespace nsg::frames

// The observation ladder (`generate --ladder`) on the e2e release (5 scenes): rung tiles are
// their split tiles rebuilt from the first k scenes that saw them, and the bytes depend on
// neither the thread count nor the share count.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>

#include "generate_fixture.h"
#include "nsg/core/files.h"
#include "nsg/io/dataset.h"
#include "nsg/io/raster.h"
#include "nsg/io/tile_meta.h"
#include "test_support.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace nsg::test {
namespace {

// Every tile of the dataset by key, split tiles and rung tiles alike.
std::map<std::string, io::DatasetTile> all_tiles(const io::Dataset& ds) {
  std::map<std::string, io::DatasetTile> out;
  const auto keep = [&](const io::DatasetTile& t) {
    out.emplace(t.key, t);
    return true;
  };
  ds.for_each_tile("", keep);
  for (int rung : ds.rungs()) ds.for_each_rung_tile("", rung, keep);
  return out;
}

// The scene names of the release by first-sample timestamp.
std::vector<std::string> scenes_by_capture_time(const fs::path& release) {
  const json scenes = read_json(release / "v1.0-mini" / "scene.json");
  const json samples = read_json(release / "v1.0-mini" / "sample.json");
  std::map<std::string, int64_t> time_of_sample;
  for (const json& s : samples) time_of_sample[s["token"]] = s["timestamp"].get<int64_t>();
  std::vector<std::pair<int64_t, std::string>> order;
  for (const json& s : scenes) order.emplace_back(time_of_sample.at(s["first_sample_token"]), s["name"]);
  std::sort(order.begin(), order.end());
  std::vector<std::string> names;
  for (const auto& [t, name] : order) names.push_back(name);
  return names;
}

TEST(GenerateLadder, TheManifestListsEveryRungOfEveryTestTileAndTheDatasetValidates) {
  const fs::path dataset = e2e_ladder_dataset();
  const io::Dataset ds = io::Dataset::open(dataset);
  ASSERT_TRUE(ds.manifest().ladder);
  const io::Ladder& ladder = *ds.manifest().ladder;
  EXPECT_EQ(ladder.rungs, (std::vector<int>{1, 2, 4, io::kRungAll}));
  EXPECT_EQ(ladder.order, "time");
  EXPECT_EQ(ds.rungs(), (std::vector<int>{1, 2, 4}));
  const int64_t test_tiles = ds.manifest().counts.test.tiles;
  ASSERT_GT(test_tiles, 2);
  ASSERT_EQ(ladder.counts.size(), 3u);
  for (const auto& [rung, count] : ladder.counts) EXPECT_EQ(count.tiles, test_tiles) << rung;
  // The split counts are the split tiles' alone.
  int64_t split_tiles = 0;
  ds.for_each_tile("test", [&](const io::DatasetTile&) { return ++split_tiles, true; });
  EXPECT_EQ(split_tiles, test_tiles);
  const CommandResult v = run_nsgraph({"validate", "--dataset", dataset.string(), "--quiet"});
  EXPECT_EQ(v.exit_code, 0) << v.out << v.err;
}

TEST(GenerateLadder, ARungTileIsItsSplitTileFromItsFirstScenesByCaptureTime) {
  const io::Dataset ds = io::Dataset::open(e2e_ladder_dataset());
  const std::vector<std::string> by_time = scenes_by_capture_time(e2e_release());
  const std::map<std::string, io::DatasetTile> tiles = all_tiles(ds);
  int checked = 0, fewer_scenes = 0;
  for (const auto& [key, base] : tiles) {
    if (base.meta().split != "test" || base.meta().ladder) continue;
    const io::TileMeta bm = base.meta();
    const io::Raster base_lidar = base.raster("lidar.tif");
    std::vector<std::string> seen;  // the split tile's scenes in capture order
    for (const std::string& s : by_time)
      if (std::count(bm.scenes.begin(), bm.scenes.end(), s)) seen.push_back(s);
    std::set<size_t> previous_pixels;
    for (int rung : {1, 2, 4}) {
      const std::string rk = key + "-r" + std::to_string(rung);
      ASSERT_TRUE(tiles.count(rk)) << rk;
      const io::DatasetTile& t = tiles.at(rk);
      const io::TileMeta m = t.meta();
      ASSERT_TRUE(m.ladder) << rk;
      EXPECT_EQ(m.ladder->rung, rung);
      EXPECT_EQ(m.ladder->base_key, key);
      EXPECT_EQ(m.ladder->scenes_seen, static_cast<int64_t>(bm.scenes.size()));
      EXPECT_EQ(m.bounds_m, bm.bounds_m);
      EXPECT_EQ(m.region, bm.region);
      // The first min(k, n) scenes by capture time, listed in table order like every tile's.
      std::vector<std::string> want(seen.begin(), seen.begin() + std::min<size_t>(rung, seen.size()));
      std::vector<std::string> got = m.scenes;
      std::sort(want.begin(), want.end());
      std::sort(got.begin(), got.end());
      EXPECT_EQ(got, want) << rk;
      EXPECT_EQ(m.ladder->capture_dates.size(), m.scenes.size());
      // Same graph under the rung key.
      json g = t.json("graph.json"), bg = base.json("graph.json");
      EXPECT_EQ(g["key"], rk);
      g.erase("key");
      bg.erase("key");
      EXPECT_EQ(g, bg) << rk;
      // LiDAR: fewer scenes cover no pixel the split tile lacks, and each rung covers what
      // the one below covered; with every scene that saw the tile it is the split tile's.
      const io::Raster lidar = t.raster("lidar.tif");
      std::set<size_t> pixels;
      for (size_t i = 0; i < lidar.data.size(); ++i)
        if (lidar.data[i] != 0) {
          pixels.insert(i);
          EXPECT_NE(base_lidar.data[i], 0) << rk << " pixel " << i;
        }
      for (size_t i : previous_pixels) EXPECT_TRUE(pixels.count(i)) << rk << " lost pixel " << i;
      previous_pixels = pixels;
      if (static_cast<size_t>(rung) >= seen.size()) {
        EXPECT_EQ(lidar.data, base_lidar.data) << rk;
      } else {
        ++fewer_scenes;
        EXPECT_LT(pixels.size(), static_cast<size_t>(std::count_if(base_lidar.data.begin(), base_lidar.data.end(),
                                                                   [](uint8_t v) { return v != 0; })))
            << rk;
      }
      ++checked;
    }
  }
  EXPECT_GT(checked, 6);
  EXPECT_GT(fewer_scenes, 0) << "no test tile was seen by more than one scene: the ladder tests nothing";
}

TEST(GenerateLadder, OneThreadAndThreeSharesGiveTheSameBytes) {
  const fs::path reference = e2e_ladder_dataset();
  TempDir one("ladder-1thread"), three("ladder-3shares");
  std::vector<std::string> args = e2e_ladder_args(one.path());
  args.insert(args.end(), {"--threads", "1"});
  ASSERT_EQ(run_nsgraph(args).exit_code, 0);
  EXPECT_EQ(tree_hashes(one.path()), tree_hashes(reference));
  for (int i = 0; i < 3; ++i) {
    args = e2e_ladder_args(three.path());
    args.insert(args.end(), {"--shard-index", std::to_string(i), "--num-shards", "3"});
    const CommandResult r = run_nsgraph(args);
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  const CommandResult merged = run_nsgraph({"merge", "--out", three.path().string()});
  ASSERT_EQ(merged.exit_code, 0) << merged.err;
  EXPECT_EQ(tree_hashes(three.path()), tree_hashes(reference));
}

TEST(GenerateLadder, ASeededOrderDiffersFromTimeAndAFolderLayoutRungTileIsChecked) {
  TempDir out("ladder-seeded");
  std::vector<std::string> args = e2e_generate_args(out.path());
  args.insert(args.end(), {"--set", "ladder.order=\"seeded\"", "--set", "ladder.rungs=[1]", "--layout", "folder"});
  const CommandResult r = run_nsgraph(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::is_directory(out / "tiles/test-r1"));
  const CommandResult v = run_nsgraph({"validate", "--dataset", out.path().string(), "--quiet"});
  EXPECT_EQ(v.exit_code, 0) << v.out << v.err;
  const io::Dataset ds = io::Dataset::open(out.path());
  EXPECT_EQ(ds.rungs(), std::vector<int>{1});
  EXPECT_EQ(ds.manifest().ladder->rungs, std::vector<int>{1});
  // Rung 1 by a seeded shuffle picks another first scene than capture time on some tile.
  std::map<std::string, std::vector<std::string>> by_time;
  io::Dataset::open(e2e_ladder_dataset()).for_each_rung_tile("test", 1, [&](const io::DatasetTile& t) {
    by_time[t.key] = t.meta().scenes;
    return true;
  });
  int tiles = 0, differ = 0;
  std::string a_key;
  ds.for_each_rung_tile("test", 1, [&](const io::DatasetTile& t) {
    EXPECT_EQ(t.meta().ladder->order, "seeded");
    differ += by_time.at(t.key) != t.meta().scenes;
    a_key = t.key;
    return ++tiles, true;
  });
  EXPECT_EQ(tiles, ds.manifest().counts.test.tiles);
  EXPECT_GT(differ, 0);
  // A rung tile claiming a scene its split tile never saw, and another rung, is named.
  const fs::path meta_file = out / ("tiles/test-r1/" + a_key + "/" + a_key + ".meta.json");
  json meta = read_json(meta_file);
  meta["scenes"].push_back("scene-9999");
  meta["ladder"]["capture_dates"].push_back("2018-07-23");
  meta["ladder"]["rung"] = 2;
  write_text(meta_file, meta.dump(2));
  const CommandResult bad =
      run_nsgraph({"validate", "--dataset", out.path().string(), "--quiet", "--checks", "ladder.rungs"});
  EXPECT_EQ(bad.exit_code, 1) << bad.out << bad.err;
  const std::string said = bad.out + bad.err;
  EXPECT_NE(said.find(a_key + ".meta.json:/ladder/rung"), std::string::npos) << said;
  EXPECT_NE(said.find("'scene-9999' is not"), std::string::npos) << said;
}

// The submission-format graph of a tile (its graph.json without ids).
json submission_graph(const io::DatasetTile& t) {
  const json g = t.json("graph.json");
  json nodes = json::array(), edges = json::array();
  std::map<std::string, size_t> index;
  for (const json& n : g["nodes"]) {
    index[n["id"].dump()] = nodes.size();
    nodes.push_back({n["u"], n["v"]});
  }
  for (const json& e : g["edges"]) edges.push_back({index.at(e["source"].dump()), index.at(e["target"].dump())});
  return {{"nodes", nodes}, {"edges", edges}};
}

// A submission perfect at rung "all" and 2, empty at rung 1, missing at rung 4: each rung's
// numbers are known, and so are the paired differences.
TEST(GenerateLadder, ScoreReportsEveryMetricPerRungWithPairedDifferences) {
  const fs::path dataset = e2e_ladder_dataset();
  const io::Dataset ds = io::Dataset::open(dataset);
  json tiles = json::object();
  int64_t n = 0;
  ds.for_each_tile("test", [&](const io::DatasetTile& t) {
    tiles[t.key] = submission_graph(t);
    tiles[t.key + "-r2"] = submission_graph(t);
    tiles[t.key + "-r1"] = {{"nodes", json::array()}, {"edges", json::array()}};
    return ++n, true;
  });
  TempDir dir("ladder-score");
  write_text(dir / "sub.json", json({{"schema_version", "1"}, {"tiles", tiles}}).dump());
  const CommandResult r = run_nsgraph({"score", "--quiet", "--ground-truth", dataset.string(), "--submission",
                                       (dir / "sub.json").string(), "--out", (dir / "report.json").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json report = read_json(dir / "report.json");
  EXPECT_EQ(report["aggregate"]["n_tiles"], n);
  EXPECT_EQ(report["aggregate"]["n_missing_predictions"], 0);
  EXPECT_EQ(report["aggregate"]["n_extra_predictions"], 0) << "rung tiles are not extra tiles of the split";
  EXPECT_DOUBLE_EQ(report["aggregate"]["mean"]["apls"].get<double>(), 1.0);
  const json& rungs = report["rungs"];
  ASSERT_EQ(rungs.size(), 3u);  // the rungs the submission holds, then "all"
  EXPECT_EQ(rungs[0]["rung"], "1");
  EXPECT_EQ(rungs[1]["rung"], "2");
  EXPECT_EQ(rungs[2]["rung"], "all");
  for (const json& rung : rungs) {
    EXPECT_EQ(rung["tiles"], n);
    EXPECT_EQ(rung["missing"], 0);
  }
  EXPECT_DOUBLE_EQ(rungs[0]["metrics"]["apls"]["mean"].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(rungs[0]["metrics"]["apls"]["se"].get<double>(), 0.0);
  EXPECT_EQ(rungs[0]["metrics"]["apls"]["n"], report["aggregate"]["n_defined"]["apls"]);
  EXPECT_DOUBLE_EQ(rungs[1]["metrics"]["apls"]["mean"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(rungs[0]["vs_all"]["apls"]["mean"].get<double>(), -1.0);
  EXPECT_DOUBLE_EQ(rungs[1]["vs_previous"]["apls"]["mean"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(rungs[1]["vs_all"]["apls"]["mean"].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(rungs[2]["vs_previous"]["apls"]["mean"].get<double>(), 0.0);
  EXPECT_FALSE(rungs[2].contains("vs_all"));
  EXPECT_FALSE(rungs[0].contains("vs_previous"));
  // validate --submission knows the rung keys, and only the rungs the dataset has.
  CommandResult v = run_nsgraph(
      {"validate", "--submission", (dir / "sub.json").string(), "--dataset", dataset.string(), "--split", "test"});
  EXPECT_EQ(v.exit_code, 0) << v.out << v.err;
  tiles[tiles.begin().key() + "-r3"] = tiles.begin().value();
  write_text(dir / "sub3.json", json({{"schema_version", "1"}, {"tiles", tiles}}).dump());
  v = run_nsgraph(
      {"validate", "--submission", (dir / "sub3.json").string(), "--dataset", dataset.string(), "--split", "test"});
  EXPECT_EQ(v.exit_code, 1);
  EXPECT_NE((v.out + v.err).find("-r3"), std::string::npos) << v.out << v.err;
}

// The real key frame (tests/data/real/scene-0061-keyframe: one scene, one sweep): its crops
// need sparse-data settings, and every rung is that one scene — so each rung tile holds the
// split tile's LiDAR layer byte for byte, records one scene seen, and the dataset validates.
TEST(GenerateLadder, TheRealKeyFrameGivesRungsOfItsOneSceneAndValidates) {
  TempDir out("ladder-real");
  const CommandResult r = run_nsgraph(real_keyframe_ladder_args(out.path()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const io::Dataset ds = io::Dataset::open(out.path());
  EXPECT_EQ(ds.rungs(), (std::vector<int>{1, 2, 4}));
  std::map<std::string, std::vector<uint8_t>> lidar;
  ds.for_each_tile("test", [&](const io::DatasetTile& t) {
    lidar[t.key] = t.files.at("lidar.tif");
    return true;
  });
  ASSERT_FALSE(lidar.empty());
  size_t rung_tiles = 0;
  ds.for_each_rung_tile("test", 0, [&](const io::DatasetTile& t) {
    const io::TileMeta m = t.meta();
    EXPECT_EQ(m.ladder->scenes_seen, 1) << t.key;
    EXPECT_EQ(m.scenes, std::vector<std::string>{"scene-0061"}) << t.key;
    EXPECT_EQ(t.files.at("lidar.tif"), lidar.at(m.ladder->base_key)) << t.key;
    ++rung_tiles;
    return true;
  });
  EXPECT_EQ(rung_tiles, 3 * lidar.size());
  const CommandResult v = run_nsgraph({"validate", "--dataset", out.path().string(), "--quiet"});
  EXPECT_EQ(v.exit_code, 0) << v.out << v.err;
}

TEST(GenerateLadder, BadRungsAreNamed) {
  TempDir out("ladder-bad");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"ladder.rungs=[2, 1]", "ladder.rungs[1]"},      {"ladder.rungs=[\"all\", 1]", "ladder.rungs[1]"},
      {"ladder.rungs=[0]", "ladder.rungs[0]"},         {"ladder.rungs=[1.5]", "ladder.rungs[0]"},
      {"ladder.splits=[\"dev\"]", "ladder.splits[0]"}, {"ladder.splits=[]", "ladder.splits"},
      {"ladder.order=\"random\"", "ladder.order"},
  };
  for (const auto& [setting, named] : cases) {
    std::vector<std::string> args = e2e_generate_args(out.path());
    args.insert(args.end(), {"--set", setting});
    const CommandResult r = run_nsgraph(args);
    EXPECT_EQ(r.exit_code, 2) << setting;
    EXPECT_NE(r.err.find(named), std::string::npos) << setting << ": " << r.err;
  }
}

}  // namespace
}  // namespace nsg::test

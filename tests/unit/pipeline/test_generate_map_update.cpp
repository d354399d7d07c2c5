// splits.preset map-update: on a synthetic release with one map change of
// every kind, every tile is cut from the scenes captured from the changes' date on, its graph
// is the current map's and beside it the prior map's, every edge labelled with what became of
// its lane — exactly the edits changes.json lists; the ladder works on it; and on the real
// key frame with two hand-made versions of its map (the stand-in as the prior, the road-ahead
// map as the current one) the lanes are labelled removed and added.
#include <gtest/gtest.h>

#include <map>
#include <set>

#include "generate_fixture.h"
#include "nsg/core/files.h"
#include "nsg/core/sha256.h"
#include "nsg/io/dataset.h"
#include "nsg/io/tile_graph.h"
#include "test_support.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace nsg::test {
namespace {

// The e2e world over two capture days with one edit of every kind from day 1 on.
fs::path changed_release() {
  const fs::path config = source_dir() / "tests/data/synth/e2e.json";
  const std::vector<std::string> settings = {
      "scenes.capture_days=2", "changes.from_day=1",        "changes.lanes_closed=1",    "changes.turns_removed=1",
      "changes.turns_added=1", "changes.crossings_added=1", "changes.dividers_retyped=1"};
  return cached_folder("release_map_changes", nsgraph_build_key() + "-" + sha256_hex(read_file(config)).substr(0, 16),
                       [&](const fs::path& dir) {
                         std::vector<std::string> args = {"synth",         "--quiet", "--config",
                                                          config.string(), "--out",   dir.string()};
                         for (const std::string& s : settings) args.insert(args.end(), {"--set", s});
                         const CommandResult r = run_nsgraph(args);
                         if (r.exit_code != 0) throw std::runtime_error("synth failed: " + r.err);
                       });
}

std::vector<std::string> map_update_args(const fs::path& release, const fs::path& out, const std::string& date) {
  return {"generate",   "--quiet",
          "--config",   (source_dir() / "tests/data/generate/e2e.json").string(),
          "--dataroot", release.string(),
          "--version",  "v1.0-mini",
          "--out",      out.string(),
          "--set",      "splits.preset=map-update",
          "--set",      "splits.before_after_date=" + date};
}

TEST(GenerateMapUpdate, TilesAreFromAfterTheDateWithBothGraphsLabelledAsTheEditsSay) {
  const fs::path release = changed_release();
  const json changes = read_json(release / "changes.json");
  const std::string date = changes["date"];
  std::set<std::string> removed, added, retyped;
  for (const json& e : changes["edits"]) {
    for (const json& t : e["removed"]) removed.insert(t.get<std::string>());
    for (const json& t : e["added"]) added.insert(t.get<std::string>());
    // a retyped divider, then its lanes: the lanes are graph elements
    for (size_t k = 1; k < e["retyped"].size(); ++k) retyped.insert(e["retyped"][k].get<std::string>());
  }
  for (const json& e : changes["edits"])  // a ped_crossing is no lane
    if (e["kind"] == "crossing_added") added.erase(e["added"][0].get<std::string>());

  TempDir out("map-update");
  std::vector<std::string> args = map_update_args(release, out.path(), date);
  args.insert(args.end(), {"--ladder"});
  const CommandResult r = run_nsgraph(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const io::Dataset ds = io::Dataset::open(out.path());
  const nlohmann::ordered_json& mu = ds.manifest().locations.at(0).map_update;
  EXPECT_EQ(mu["date"], date);
  EXPECT_EQ(mu["prior_map"]["file"], "maps/prior/expansion/boston-seaport.json");
  EXPECT_EQ(mu["prior_map"]["sha256"], sha256_file(release / "maps/prior/expansion/boston-seaport.json"));
  EXPECT_EQ(mu["lanes"]["removed"], removed.size());
  EXPECT_EQ(mu["lanes"]["added"], added.size());
  EXPECT_EQ(mu["lanes"]["retyped"], retyped.size());
  EXPECT_EQ(mu["lanes"]["moved"], 0);

  const std::map<std::string, std::string> dates = scene_dates(release);
  std::map<std::string, int> seen;  // label → edges, over every tile of both graphs
  int tiles = 0;
  for (const std::string& split : ds.splits()) {
    ds.for_each_tile(split, [&](const io::DatasetTile& t) {
      ++tiles;
      for (const std::string& scene : t.meta().scenes) EXPECT_GE(dates.at(scene), date) << t.key << ": " << scene;
      const json doc = t.json("graph.json");
      const graph::TileGraph current = t.graph();
      const std::optional<graph::TileGraph> prior = io::tile_prior_graph_from_json(doc, t.key);
      EXPECT_TRUE(prior.has_value()) << t.key;
      for (const graph::TileEdge& e : current.edges) {
        const std::string label = graph::map_change_name(e.change);
        ++seen["current " + label];
        EXPECT_EQ(label == "added", added.count(e.lane_token) > 0) << t.key << " " << e.lane_token;
        EXPECT_EQ(label == "retyped", retyped.count(e.lane_token) > 0) << t.key;
        EXPECT_NE(label, "removed");
        EXPECT_EQ(removed.count(e.lane_token), 0u) << t.key;
      }
      if (prior)
        for (const graph::TileEdge& e : prior->edges) {
          const std::string label = graph::map_change_name(e.change);
          ++seen["prior " + label];
          EXPECT_EQ(label == "removed", removed.count(e.lane_token) > 0) << t.key;
          EXPECT_NE(label, "added");
        }
      return true;
    });
  }
  EXPECT_GT(tiles, 0);
  EXPECT_GT(seen["current unchanged"], 0);
  EXPECT_GT(seen["prior removed"], 0) << "no tile holds the closed lane or the removed turn";
  const CommandResult v = run_nsgraph({"validate", "--dataset", out.path().string(), "--quiet"});
  EXPECT_EQ(v.exit_code, 0) << v.out << v.err;

  // The copy-the-prior baseline (predict --model prior): perfect where the map did not change,
  // extra edges (precision < 1, recall 1) where the prior holds removed lanes; and on the
  // change metrics the floor: no change detected, none claimed, every unchanged sample kept.
  std::map<std::string, std::set<std::string>> labels;  // key → the labels of both its graphs
  for (const std::string& split : ds.splits())
    ds.for_each_tile(split, [&](const io::DatasetTile& t) {
      const json doc = t.json("graph.json");
      for (const json* g : {&doc, &doc["prior"]})
        for (const json& e : (*g)["edges"]) labels[t.key].insert(e["change"].get<std::string>());
      return true;
    });
  int unchanged_tiles = 0, removed_tiles = 0;
  int64_t change_samples = 0;           // over both splits: the edits leave samples where the two maps differ
  TempDir scored("map-update-scored");  // not in the dataset: its bytes are compared below
  for (const std::string& split : {"train", "test"}) {
    if (ds.tile_count(split) == 0) continue;
    const fs::path sub = scored / (split + "-prior.json"), report = scored / (split + "-report.json");
    const CommandResult p = run_nsgraph({"predict", "--quiet", "--model", "prior", "--dataset", out.path().string(),
                                         "--split", split, "--out", sub.string()});
    ASSERT_EQ(p.exit_code, 0) << p.err;
    const CommandResult sc = run_nsgraph({"score", "--quiet", "--ground-truth", out.path().string(), "--split", split,
                                          "--submission", sub.string(), "--out", report.string()});
    ASSERT_EQ(sc.exit_code, 0) << sc.err;
    const json scores = read_json(report);
    const json& pooled = scores["aggregate"]["pooled"];
    change_samples += scores["aggregate"]["sums"]["change_samples"].get<int64_t>();
    if (!pooled["change_recall"].is_null()) EXPECT_EQ(pooled["change_recall"], 0.0) << split;
    EXPECT_TRUE(pooled["change_precision"].is_null()) << split << ": copying the prior claims no change";
    EXPECT_EQ(pooled["false_change_rate"], 0.0) << split;
    for (const auto& [key, tile] : scores["tiles"].items()) {
      EXPECT_FALSE(tile["change_recall"].is_number() && tile["change_recall"] != 0.0) << key;
      EXPECT_FALSE(tile["unchanged_precision"].is_number() && tile["unchanged_precision"] != 1.0) << key;
      EXPECT_FALSE(tile["unchanged_recall"].is_number() && tile["unchanged_recall"] != 1.0) << key;
      if (tile["apls"].is_null()) continue;  // an empty tile
      if (labels[key] == std::set<std::string>{"unchanged"}) {
        ++unchanged_tiles;
        EXPECT_EQ(tile["apls"], 1.0) << key;
        EXPECT_EQ(tile["f1"], 1.0) << key;
      } else if (labels[key].count("removed") && !labels[key].count("added")) {
        ++removed_tiles;
        EXPECT_LT(tile["geo_precision"].get<double>(), 1.0) << key;
        EXPECT_EQ(tile["geo_recall"], 1.0) << key;
      }
    }
  }
  EXPECT_GT(unchanged_tiles, 0);
  EXPECT_GT(removed_tiles, 0);
  EXPECT_GT(change_samples, 0);
  const CommandResult not_map_update = run_nsgraph({"predict", "--quiet", "--model", "prior", "--dataset",
                                                    e2e_dataset().string(), "--out", (scored / "x.json").string()});
  EXPECT_EQ(not_map_update.exit_code, 2);
  EXPECT_NE(not_map_update.err.find("splits.preset map-update"), std::string::npos) << not_map_update.err;

  // The forest with the prior graph as an input layer trains and predicts on map-update tiles
  // (the e2e world has test tiles only: trained on them, a check of the mechanics);
  // on tiles without a prior graph it names what it needs (exit 2).
  const fs::path model = scored / "forest-prior.yml.gz";
  const CommandResult tr = run_nsgraph({"train", "--quiet", "--dataset", out.path().string(), "--split", "test",
                                        "--modalities", "lidar,prior", "--variant", "b1", "--model", model.string()});
  ASSERT_EQ(tr.exit_code, 0) << tr.err;
  const CommandResult pr = run_nsgraph({"predict", "--quiet", "--model", model.string(), "--dataset",
                                        out.path().string(), "--split", "test", "--out", (scored / "f.json").string()});
  EXPECT_EQ(pr.exit_code, 0) << pr.err;
  const CommandResult no_prior = run_nsgraph({"predict", "--quiet", "--model", model.string(), "--dataset",
                                              e2e_dataset().string(), "--out", (scored / "y.json").string()});
  EXPECT_EQ(no_prior.exit_code, 2);
  EXPECT_NE(no_prior.err.find("/prior"), std::string::npos) << no_prior.err;
  EXPECT_NE(no_prior.err.find("map-update"), std::string::npos) << no_prior.err;

  // Deterministic at one thread.
  TempDir one("map-update-1");
  std::vector<std::string> one_args = map_update_args(release, one.path(), date);
  one_args.insert(one_args.end(), {"--ladder", "--threads", "1"});
  ASSERT_EQ(run_nsgraph(one_args).exit_code, 0);
  EXPECT_EQ(tree_hashes(one.path()), tree_hashes(out.path()));
}

TEST(GenerateMapUpdate, OtherPresetsWriteNoPriorAndAMissingPriorMapIsNamed) {
  const fs::path release = changed_release();
  TempDir out("map-update-plain");
  const CommandResult r =
      run_nsgraph({"generate", "--quiet", "--config", (source_dir() / "tests/data/generate/e2e.json").string(),
                   "--dataroot", release.string(), "--version", "v1.0-mini", "--out", (out / "regions").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const io::Dataset ds = io::Dataset::open(out / "regions");
  EXPECT_TRUE(ds.manifest().locations.at(0).map_update.is_null());
  ds.for_each_tile("test", [&](const io::DatasetTile& t) {
    const json doc = t.json("graph.json");
    EXPECT_FALSE(doc.contains("prior")) << t.key;
    for (const json& e : doc["edges"]) EXPECT_FALSE(e.contains("change")) << t.key;
    return true;
  });
  // A release without a prior map, and the keys' relations.
  std::vector<std::string> args =
      map_update_args(source_dir() / "tests/data/real/scene-0061-keyframe", out / "no-prior", "2018-07-24");
  CommandResult bad = run_nsgraph(args);
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("splits.prior_maps"), std::string::npos) << bad.err;
  bad = run_nsgraph({"generate", "--quiet", "--config", (source_dir() / "tests/data/generate/e2e.json").string(),
                     "--dataroot", release.string(), "--version", "v1.0-mini", "--out", (out / "x").string(), "--set",
                     "splits.prior_maps=somewhere"});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("splits.prior_maps"), std::string::npos) << bad.err;
  bad = run_nsgraph({"generate", "--quiet", "--config", (source_dir() / "tests/data/generate/e2e.json").string(),
                     "--dataroot", release.string(), "--version", "v1.0-mini", "--out", (out / "y").string(), "--set",
                     "splits.preset=map-update"});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("splits.before_after_date"), std::string::npos) << bad.err;
}

// Item 6: a real release and two versions of its map. The real key frame's stand-in map is
// the prior; the road-ahead stand-in (tests/data/real/road-ahead) the current one.
TEST(GenerateMapUpdate, TwoVersionsOfTheRealKeyFramesMapAreLabelled) {
  TempDir tmp("map-update-real");
  const fs::path release = tmp / "release";
  fs::copy(source_dir() / "tests/data/real/scene-0061-keyframe", release, fs::copy_options::recursive);
  fs::create_directories(tmp / "prior");
  fs::copy_file(release / "maps/expansion/singapore-onenorth.json", tmp / "prior/singapore-onenorth.json");
  fs::copy_file(source_dir() / "tests/data/real/road-ahead/singapore-onenorth.json",
                release / "maps/expansion/singapore-onenorth.json", fs::copy_options::overwrite_existing);
  const std::string prior_lane = read_json(tmp / "prior/singapore-onenorth.json")["lane"][0]["token"];
  const std::string current_lane = read_json(release / "maps/expansion/singapore-onenorth.json")["lane"][0]["token"];
  std::vector<std::string> args = real_keyframe_ladder_args(tmp / "dataset");
  args.erase(std::find(args.begin(), args.end(), "--ladder"));
  *(std::find(args.begin(), args.end(), "--dataroot") + 1) = release.string();
  args.insert(args.end(), {"--set", "splits.preset=map-update", "--set", "splits.before_after_date=2018-07-24", "--set",
                           "splits.prior_maps=" + (tmp / "prior").string()});
  const CommandResult r = run_nsgraph(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const io::Dataset ds = io::Dataset::open(tmp / "dataset");
  const nlohmann::ordered_json& mu = ds.manifest().locations.at(0).map_update;
  EXPECT_EQ(mu["lanes"]["added"], 1);
  EXPECT_EQ(mu["lanes"]["removed"], 1);
  EXPECT_EQ(mu["prior_map"]["file"], (tmp / "prior/singapore-onenorth.json").string());
  std::set<std::string> current_labels, prior_labels;
  ds.for_each_tile("test", [&](const io::DatasetTile& t) {
    for (const graph::TileEdge& e : t.graph().edges) {
      EXPECT_EQ(e.lane_token, current_lane);
      current_labels.insert(graph::map_change_name(e.change));
    }
    const std::optional<graph::TileGraph> prior = io::tile_prior_graph_from_json(t.json("graph.json"), t.key);
    for (const graph::TileEdge& e : prior->edges) {
      EXPECT_EQ(e.lane_token, prior_lane);
      prior_labels.insert(graph::map_change_name(e.change));
    }
    return true;
  });
  EXPECT_EQ(current_labels, (std::set<std::string>{"added"}));
  EXPECT_EQ(prior_labels, (std::set<std::string>{"removed"}));

  // The change metrics on the real key frame: the prior's lane (under the ego) and the
  // current one (the road ahead) differ, so copying the prior detects no change where it
  // has samples of both kinds.
  const fs::path sub = tmp / "prior.json", report = tmp / "report.json";
  ASSERT_EQ(run_nsgraph({"predict", "--quiet", "--model", "prior", "--dataset", (tmp / "dataset").string(), "--split",
                         "test", "--out", sub.string()})
                .exit_code,
            0);
  const CommandResult sc = run_nsgraph({"score", "--quiet", "--ground-truth", (tmp / "dataset").string(), "--split",
                                        "test", "--submission", sub.string(), "--out", report.string()});
  ASSERT_EQ(sc.exit_code, 0) << sc.err;
  const json scored = read_json(report)["aggregate"];
  EXPECT_GT(scored["sums"]["change_samples_added"].get<int64_t>(), 0);
  EXPECT_GT(scored["sums"]["change_samples_removed"].get<int64_t>(), 0);
  EXPECT_EQ(scored["pooled"]["change_recall"], 0.0);
  EXPECT_TRUE(scored["pooled"]["change_precision"].is_null());
}

}  // namespace
}  // namespace nsg::test

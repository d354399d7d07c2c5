// `generate`'s scene exclusion (config scenes.exclude) and its refusal of an empty dataset,
// on the small synthetic releases.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>

#include "generate_fixture.h"
#include "nsg/core/files.h"
#include "test_support.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace nsg::test {
namespace {

std::vector<std::string> generate_args(const fs::path& release, const fs::path& out, const std::string& config) {
  return {"generate", "--config",   config,     "--dataroot", release.string(), "--version",    "v1.0-mini",
          "--out",    out.string(), "--layout", "folder",     "--no-rgb",       "--no-semantic"};
}

std::string e2e_config() { return (source_dir() / "tests/data/generate/e2e.json").string(); }

// key → meta.json of every tile of a folder-layout dataset.
std::map<std::string, json> tile_metas(const fs::path& dataset) {
  std::map<std::string, json> metas;
  for (const auto& e : fs::recursive_directory_iterator(dataset / "tiles")) {
    const std::string name = e.path().filename().string();
    const std::string suffix = ".meta.json";
    if (name.size() > suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0)
      metas[name.substr(0, name.size() - suffix.size())] = read_json(e.path());
  }
  return metas;
}

bool any_tile_names_scene(const std::map<std::string, json>& metas, const std::string& scene) {
  for (const auto& [key, meta] : metas)
    for (const json& s : meta["scenes"])
      if (s == scene) return true;
  return false;
}

// One scene of the e2e release renamed to a known-bad real scene: left out by default,
// kept with scenes.exclude=[].
TEST(GenerateScenes, AKnownBadSceneContributesNothingAndTheManifestSaysWhy) {
  TempDir dir("gen-exclude");
  const fs::path release =
      release_with_renamed_scene(e2e_release(), "v1.0-mini", "scene-0061", "scene-0499", dir / "release");

  const CommandResult excluded = run_nsgraph(generate_args(release, dir / "default", e2e_config()));
  ASSERT_EQ(excluded.exit_code, 0) << excluded.err;
  EXPECT_NE(excluded.err.find("leaving out 1 scene(s) (scenes.exclude): scene-0499 (boston-seaport: the ego poses fit "
                              "the map badly"),
            std::string::npos)
      << excluded.err;
  const json m = read_json(dir / "default/manifest.json");
  ASSERT_EQ(m["excluded_scenes"].size(), 1u) << m["excluded_scenes"];
  EXPECT_EQ(m["excluded_scenes"][0]["name"], "scene-0499");
  EXPECT_EQ(m["excluded_scenes"][0]["location"], "boston-seaport");
  EXPECT_NE(m["excluded_scenes"][0]["reason"].get<std::string>().find("map_api blacklist"), std::string::npos);
  EXPECT_EQ(m["locations"][0]["scenes"]["used"], 4);
  EXPECT_EQ(m["locations"][0]["scenes"]["excluded"][0]["name"], "scene-0499");
  EXPECT_EQ(m["config"]["scenes"]["exclude"].size(), 5u) << "the configured list is recorded as well";
  const auto metas_excluded = tile_metas(dir / "default");
  ASSERT_FALSE(metas_excluded.empty());
  EXPECT_FALSE(any_tile_names_scene(metas_excluded, "scene-0499"));

  std::vector<std::string> args = generate_args(release, dir / "kept", e2e_config());
  args.insert(args.end(), {"--set", "scenes.exclude=[]"});
  const CommandResult kept = run_nsgraph(args);
  ASSERT_EQ(kept.exit_code, 0) << kept.err;
  EXPECT_EQ(kept.err.find("leaving out"), std::string::npos) << kept.err;
  const json k = read_json(dir / "kept/manifest.json");
  EXPECT_TRUE(k["excluded_scenes"].empty());
  EXPECT_EQ(k["locations"][0]["scenes"]["used"], 5);
  EXPECT_TRUE(k["config"]["scenes"]["exclude"].empty());
  const auto metas_kept = tile_metas(dir / "kept");
  EXPECT_TRUE(any_tile_names_scene(metas_kept, "scene-0499")) << "the scene's sweeps reach the tiles when kept";
  // Its sweeps change the LiDAR of the tiles (coverage of the same crops, or the crops).
  std::map<std::string, double> cov_excluded, cov_kept;
  for (const auto& [key, meta] : metas_excluded) cov_excluded[key] = meta["coverage"]["lidar"].get<double>();
  for (const auto& [key, meta] : metas_kept) cov_kept[key] = meta["coverage"]["lidar"].get<double>();
  EXPECT_NE(cov_excluded, cov_kept);

  // A list of one's own, through --set.
  args = generate_args(release, dir / "own", e2e_config());
  args.insert(args.end(), {"--set", R"(scenes.exclude=[{"name": "scene-0553", "reason": "seen twice"}])"});
  const CommandResult own = run_nsgraph(args);
  ASSERT_EQ(own.exit_code, 0) << own.err;
  const json o = read_json(dir / "own/manifest.json");
  ASSERT_EQ(o["excluded_scenes"].size(), 1u);
  EXPECT_EQ(o["excluded_scenes"][0]["name"], "scene-0553");
  EXPECT_EQ(o["excluded_scenes"][0]["reason"], "seen twice");
  EXPECT_FALSE(any_tile_names_scene(tile_metas(dir / "own"), "scene-0553"));
  EXPECT_TRUE(any_tile_names_scene(tile_metas(dir / "own"), "scene-0499"));
}

TEST(GenerateConfig, SceneExcludeDefaultsToTheKnownBadScenesAndIsSettable) {
  CommandResult r = run_nsgraph({"generate", "--print-config"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::vector<std::string> names;
  const json config = json::parse(r.out);
  for (const json& e : config["scenes"]["exclude"]) {
    names.push_back(e["name"].get<std::string>());
    EXPECT_FALSE(e["reason"].get<std::string>().empty());
  }
  EXPECT_EQ(names, (std::vector<std::string>{"scene-0499", "scene-0501", "scene-0502", "scene-0515", "scene-0517"}));
  r = run_nsgraph({"generate", "--print-config", "--set", "scenes.exclude=[]"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(json::parse(r.out)["scenes"]["exclude"].empty());
  r = run_nsgraph({"generate", "--print-config", "--set", "scenes.exclude=scene-0499"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("scenes.exclude"), std::string::npos) << r.err;
  r = run_nsgraph({"generate", "--print-config", "--set",
                   R"(scenes.exclude=[{"name": "scene-0001", "reason": ""}, {"name": "scene-0001", "reason": ""}])"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("scene-0001"), std::string::npos) << r.err;
  r = run_nsgraph({"generate", "--print-config", "--set", R"(scenes.exclude=[{"name": "scene-0001"}])"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("scenes.exclude[0]"), std::string::npos) << r.err;
}

// Default config on samples/synth/tiny.json: the candidates are dropped, the run says by
// what and exits 1; --allow-empty writes the empty dataset.
TEST(GenerateEmpty, TinyReleaseWithTheDefaultConfigIsRefusedNamingTheFilter) {
  TempDir dir("gen-empty-tiny");
  const fs::path release = tiny_release();
  const std::vector<std::string> base = {"generate",      "--dataroot", release.string(),
                                         "--version",     "v1.0-mini",  "--no-rgb",
                                         "--no-semantic", "--out",      (dir / "out").string()};
  CommandResult r = run_nsgraph(base);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("the dataset would hold no tiles (0 train / 0 val / 0 test)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("boston-seaport: 2 scene(s) used"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("below crops.min_lidar_coverage = 0.5"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--set crops.min_lidar_coverage=0."), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--allow-empty"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out/manifest.json"));

  std::vector<std::string> args = base;
  args.push_back("--allow-empty");
  r = run_nsgraph(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("no tiles"), std::string::npos) << r.err;
  const json m = read_json(dir / "out/manifest.json");
  EXPECT_EQ(m["counts"]["total_tiles"], 0);

  // Every scene excluded: the location has no LiDAR, and the message says why.
  args = base;
  args.back() = (dir / "none").string();
  args.insert(args.end(), {"--set", R"(scenes.exclude=[{"name": "scene-0061", "reason": "a"},
                                                         {"name": "scene-0553", "reason": "b"}])"});
  r = run_nsgraph(args);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("0 scene(s) used, 2 left out by scenes.exclude (every scene of the location is excluded)"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("--set 'scenes.exclude=[]'"), std::string::npos) << r.err;
}

// Every share computes the whole plan: all of them refuse an empty dataset alike, and
// nothing can be merged.
TEST(GenerateEmpty, EveryShareRefusesTheSameEmptyPlan) {
  TempDir dir("gen-empty-shares");
  std::string first_message;
  for (int i = 0; i < 2; ++i) {
    std::vector<std::string> args = generate_args(e2e_release(), dir.path(), e2e_config());
    args.insert(args.end(), {"--set", "crops.min_lidar_coverage=1", "--shard-index", std::to_string(i), "--num-shards",
                             "2", "--quiet"});
    const CommandResult r = run_nsgraph(args);
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_NE(r.err.find("train: 1 region(s)"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("test: 1 region(s)"), std::string::npos) << r.err;
    if (i == 0) first_message = r.err;
    EXPECT_EQ(r.err, first_message) << "shares explain the same plan";
  }
  const CommandResult merged = run_nsgraph({"merge", "--out", dir.path().string()});
  EXPECT_EQ(merged.exit_code, 2) << merged.err;
  EXPECT_NE(merged.err.find("not finished"), std::string::npos) << merged.err;
  EXPECT_FALSE(fs::exists(dir / "manifest.json"));
}

// A split that ends with no tile while the others have some is a warning, not an error.
TEST(GenerateEmpty, ASplitWithoutTilesIsAWarning) {
  TempDir dir("gen-empty-split");
  json config = read_json(e2e_config());
  // The test region moved off the synthetic map (300 × 300 m): no LiDAR there.
  config["splits"]["regions"]["boston-seaport"][1]["bounds_m"] = {400.0, 400.0, 500.0, 500.0};
  write_text(dir / "config.json", config.dump());
  const CommandResult r = run_nsgraph(generate_args(e2e_release(), dir / "out", (dir / "config.json").string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("warning: generate: the test split has no tiles (train "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("test: 1 region(s) with 0.0000 km² of LiDAR"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("the val split"), std::string::npos) << "val is not asked for: " << r.err;
  const json m = read_json(dir / "out/manifest.json");
  EXPECT_GT(m["counts"]["train"]["tiles"].get<int>(), 0);
  EXPECT_EQ(m["counts"]["test"]["tiles"], 0);
}

}  // namespace
}  // namespace nsg::test

namespace nsg::test {
namespace {

// A view of `release` under `dir`: its folders recreated, its files symlinked (cheap to
// make and to break one file of).
fs::path release_view(const fs::path& release, const fs::path& dir) {
  const fs::path view = dir / "release", from = fs::absolute(release);
  fs::create_directories(view);
  for (const auto& e : fs::recursive_directory_iterator(from)) {
    const fs::path to = view / fs::relative(e.path(), from);
    if (e.is_directory()) fs::create_directories(to);
    else fs::create_symlink(e.path(), to);
  }
  return view;
}

// Every file a run would open is checked before the first heavy stage, and
// `generate --check-inputs` runs only that: a missing sweep or mask was found only when its
// stage reached it (after the LiDAR stage: minutes on trainval).
TEST(GenerateInputs, CheckInputsNamesTheFirstMissingFileAndWritesNothing) {
  TempDir dir("gen-inputs");
  const fs::path view = release_view(e2e_release(), dir.path());
  std::vector<std::string> args = e2e_generate_args(dir / "out");
  for (size_t i = 0; i + 1 < args.size(); ++i)
    if (args[i] == "--dataroot") args[i + 1] = view.string();
  args.erase(std::find(args.begin(), args.end(), "--quiet"));
  args.push_back("--check-inputs");
  CommandResult r = run_nsgraph(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("generate: inputs present: 5 scene(s), 1 map expansion(s)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("nothing written"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out"));

  // One sweep (not a key frame) gone.
  fs::path sweep;
  for (const auto& e : fs::directory_iterator(view / "sweeps" / "LIDAR_TOP")) sweep = std::max(sweep, e.path());
  ASSERT_FALSE(sweep.empty());
  const fs::path sweep_target = fs::read_symlink(sweep);
  fs::remove(sweep);
  r = run_nsgraph(args);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(sweep.string()), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("LiDAR sweeps (1 missing, this one first)"), std::string::npos) << r.err;
  // A real run stops there too, before the LiDAR stage and without a manifest.
  std::vector<std::string> real_run(args.begin(), args.end() - 1);
  r = run_nsgraph(real_run);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(r.err.find("accumulating LiDAR"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out" / "manifest.json"));
  fs::create_symlink(sweep_target, sweep);

  // One mask gone: the default semantic_source auto takes the masks (their folder is
  // there), so the missing one is named; without semantics the inputs are complete.
  fs::path mask;
  for (const auto& e : fs::directory_iterator(view / "semantic" / "CAM_FRONT")) mask = std::max(mask, e.path());
  ASSERT_FALSE(mask.empty());
  fs::remove(mask);
  r = run_nsgraph(args);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(mask.string()), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("semantic masks"), std::string::npos) << r.err;
  args.push_back("--no-semantic");
  r = run_nsgraph(args);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("0 mask(s)"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace nsg::test

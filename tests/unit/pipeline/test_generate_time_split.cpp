// splits.preset before-after on the e2e world captured over two days (scenes.capture_days 2):
// train tiles only from the scenes before the date, test tiles only from those after, the
// leakage figures in the manifest, and the config's relations named.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <regex>
#include <tuple>

#include "generate_fixture.h"
#include "nsg/core/files.h"
#include "nsg/core/sha256.h"
#include "nsg/io/dataset.h"
#include "test_support.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace nsg::test {
namespace {

// The e2e release with its 5 scenes over two capture days (3 on the first, 2 on the second).
fs::path two_day_release() {
  const fs::path config = source_dir() / "tests/data/synth/e2e.json";
  return cached_folder("release_two_days", nsgraph_build_key() + "-" + sha256_hex(read_file(config)).substr(0, 16),
                       [&](const fs::path& dir) {
                         const CommandResult r = run_nsgraph({"synth", "--quiet", "--config", config.string(), "--set",
                                                              "scenes.capture_days=2", "--out", dir.string()});
                         if (r.exit_code != 0) throw std::runtime_error("synth failed: " + r.err);
                       });
}

std::vector<std::string> time_split_args(const fs::path& release, const fs::path& out, const std::string& date) {
  return {"generate",   "--quiet",
          "--config",   (source_dir() / "tests/data/generate/e2e.json").string(),
          "--dataroot", release.string(),
          "--version",  "v1.0-mini",
          "--out",      out.string(),
          "--set",      "splits.regions={}",
          "--set",      "splits.preset=\"before-after\"",
          "--set",      "splits.before_after_date=\"" + date + "\""};
}

TEST(GenerateTimeSplit, TrainTilesComeFromBeforeTheDateAndTestTilesFromAfter) {
  const fs::path release = two_day_release();
  const std::map<std::string, std::string> dates = scene_dates(release);
  std::string second_day;
  for (const auto& [scene, date] : dates) second_day = std::max(second_day, date);
  ASSERT_NE(dates.begin()->second, second_day) << "the release was captured on one day";
  TempDir out("time-split");
  std::vector<std::string> args = time_split_args(release, out.path(), second_day);
  args.erase(args.begin() + 1);  // not --quiet: the leakage line is printed
  const CommandResult r = run_nsgraph(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("before-after split at " + second_day), std::string::npos) << r.err;

  const io::Dataset ds = io::Dataset::open(out.path());
  const nlohmann::ordered_json& split = ds.manifest().locations.at(0).time_split;
  EXPECT_EQ(split["date"], second_day);
  EXPECT_EQ(split["scenes"]["train"], 3);
  EXPECT_EQ(split["scenes"]["test"], 2);
  const int64_t train = ds.manifest().counts.train.tiles, test = ds.manifest().counts.test.tiles;
  ASSERT_GT(train, 0);
  ASSERT_GT(test, 0);
  EXPECT_EQ(split["test_tiles"], test);
  EXPECT_LE(split["test_tiles_overlapping_train"].get<int64_t>(), test);
  for (const char* s : {"train", "test"}) {
    ds.for_each_tile(s, [&](const io::DatasetTile& t) {
      const io::TileMeta m = t.meta();
      EXPECT_FALSE(m.scenes.empty()) << t.key;
      for (const std::string& scene : m.scenes)
        EXPECT_EQ(dates.at(scene) < second_day, std::string(s) == "train") << t.key << " holds " << scene;
      return true;
    });
  }
  const CommandResult v = run_nsgraph({"validate", "--dataset", out.path().string(), "--quiet"});
  EXPECT_EQ(v.exit_code, 0) << v.out << v.err;
  // The same bytes at one thread.
  TempDir one("time-split-1");
  std::vector<std::string> one_args = time_split_args(release, one.path(), second_day);
  one_args.insert(one_args.end(), {"--threads", "1"});
  ASSERT_EQ(run_nsgraph(one_args).exit_code, 0);
  EXPECT_EQ(tree_hashes(one.path()), tree_hashes(out.path()));
}

// The memory plan's LiDAR blocks and covered cells in a -v generate log.
std::pair<uint64_t, uint64_t> planned_lidar(const std::string& log) {
  std::smatch m;
  if (!std::regex_search(log, m, std::regex("memory plan: location=\\S+ lidar_blocks=(\\d+) covered_cells=(\\d+)")))
    return {0, 0};
  return {std::stoull(m[1].str()), std::stoull(m[2].str())};
}

// Each side of the date accumulates its own layers, all held until the tiles are cut: the
// memory plan is the sum of the two sides' plans (each side alone: the regions preset with
// the other side's scenes excluded), a street both sides drove counted twice, and it agrees
// with the run's own per-side measures as a one-source plan does.
TEST(GenerateTimeSplit, TheMemoryPlanCountsBothSidesLayers) {
  const fs::path release = two_day_release();
  const std::map<std::string, std::string> dates = scene_dates(release);
  std::string second_day;
  for (const auto& [scene, date] : dates) second_day = std::max(second_day, date);
  TempDir out("time-split-memory");
  std::vector<std::string> args = time_split_args(release, out / "both", second_day);
  args[1] = "-v";
  std::swap(args[0], args[1]);  // -v generate …
  const CommandResult r = run_nsgraph(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto [blocks, cells] = planned_lidar(r.err);
  ASSERT_GT(blocks, 0u) << r.err;

  std::pair<uint64_t, uint64_t> sides{0, 0};
  for (const bool before : {true, false}) {
    json exclude = json::array();
    for (const auto& [scene, date] : dates)
      if ((date < second_day) != before) exclude.push_back({{"name", scene}, {"reason", "the other side"}});
    std::vector<std::string> one = e2e_generate_args(out / (before ? "before" : "after"));
    one[1] = "-v";
    std::swap(one[0], one[1]);
    one[5] = release.string();  // --dataroot
    one.insert(one.end(), {"--allow-empty", "--set", "scenes.exclude=" + exclude.dump()});
    const CommandResult side = run_nsgraph(one);
    const auto [b, c] = planned_lidar(side.err);
    ASSERT_GT(b, 0u) << side.err;
    sides.first += b;
    sides.second += c;
  }
  EXPECT_EQ(blocks, sides.first);
  EXPECT_EQ(cells, sides.second);

  double run_blocks = 0, run_cells = 0;
  int accumulations = 0;
  const std::regex measured("LiDAR accumulated: (\\d+) blocks, (\\d+) covered cells");
  for (auto it = std::sregex_iterator(r.err.begin(), r.err.end(), measured); it != std::sregex_iterator(); ++it) {
    run_blocks += std::stod((*it)[1].str());
    run_cells += std::stod((*it)[2].str());
    ++accumulations;
  }
  ASSERT_EQ(accumulations, 2) << r.err;
  const double block_ratio = static_cast<double>(blocks) / run_blocks;
  const double cell_ratio = static_cast<double>(cells) / run_cells;
  std::printf("[ figures ] e2e world over two days, before-after: plan / run LiDAR blocks %.2f, covered cells %.2f\n",
              block_ratio, cell_ratio);
  // The bands of GenerateMemory.EachPlanTermAgreesWithTheRunsMeasure (one source).
  EXPECT_GE(block_ratio, 0.67);
  EXPECT_LE(block_ratio, 1.5);
  EXPECT_GE(cell_ratio, 0.6);
  EXPECT_LE(cell_ratio, 1.6);
}

// A date outside the capture dates leaves one side without scenes: the warning says so by
// the date and the dates the release spans, and suggests moving the date — not the regions
// preset's advice (automatic blocks, explicit regions), which does not apply.
TEST(GenerateTimeSplit, AnEmptySideIsExplainedByTheDate) {
  const fs::path release = two_day_release();
  std::string first = "9999", last;
  for (const auto& [scene, date] : scene_dates(release)) {
    first = std::min(first, date);
    last = std::max(last, date);
  }
  const std::vector<std::tuple<std::string, std::string, std::string>> cases = {
      {"2030-01-01", "test", "no scene captured on or after 2030-01-01"},
      {"2000-01-01", "train", "no scene captured before 2000-01-01"}};
  for (const auto& [date, empty, why] : cases) {
    SCOPED_TRACE(date);
    TempDir out("time-split-empty");
    std::vector<std::string> args = time_split_args(release, out.path(), date);
    args.erase(args.begin() + 1);  // not --quiet: the warning is printed
    const CommandResult r = run_nsgraph(args);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("the " + empty + " split has no tiles"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(why), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("move splits.before_after_date (now " + date + ") inside the capture dates (" + first + " … " +
                         last + ")"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(r.err.find("automatic split"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("splits.regions"), std::string::npos) << r.err;
  }
}

// The real key frame's log.json dates its one scene 2018-07-24 (date_captured, as every real
// log has it): a split after that date puts it on the train side and explains the empty test
// side by the real capture date.
TEST(GenerateTimeSplit, TheRealKeyFramesCaptureDateDecidesItsSide) {
  TempDir out("time-split-real");
  std::vector<std::string> args = real_keyframe_ladder_args(out.path());
  args.erase(args.begin() + 1);            // not --quiet: the warning is printed
  args.erase(args.end() - 2, args.end());  // the ratios (the preset takes none)
  args.erase(std::find(args.begin(), args.end(), "--ladder"));
  args.insert(args.end(), {"--set", "splits.preset=before-after", "--set", "splits.before_after_date=2018-07-25"});
  const CommandResult r = run_nsgraph(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("1 scene(s) before (train), 0 on or after (test), captured 2018-07-24 … 2018-07-24"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("no scene captured on or after 2018-07-25"), std::string::npos) << r.err;
  const io::Dataset ds = io::Dataset::open(out.path());
  EXPECT_GT(ds.tile_count("train"), 0u);
  EXPECT_EQ(ds.tile_count("test"), 0u);
}

TEST(GenerateTimeSplit, TheRelationsOfThePresetAreNamed) {
  const fs::path release = two_day_release();
  TempDir out("time-split-bad");
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"--set", "splits.preset=\"before-after\"", "--set", "splits.regions={}"}, "splits.before_after_date"},
      {{"--set", "splits.preset=\"before-after\"", "--set", "splits.before_after_date=\"2018-07-24\""},
       "splits.regions"},
      {{"--set", "splits.before_after_date=\"2018-07-24\""}, "splits.before_after_date"},
      {{"--set", "splits.preset=\"before-after\"", "--set", "splits.regions={}", "--set",
        "splits.before_after_date=\"July\""},
       "splits.before_after_date"},
  };
  for (const auto& [settings, named] : cases) {
    std::vector<std::string> args = {
        "generate",   "--quiet",          "--config",  (source_dir() / "tests/data/generate/e2e.json").string(),
        "--dataroot", release.string(),   "--version", "v1.0-mini",
        "--out",      out.path().string()};
    args.insert(args.end(), settings.begin(), settings.end());
    const CommandResult r = run_nsgraph(args);
    EXPECT_EQ(r.exit_code, 2) << named;
    EXPECT_NE(r.err.find(named), std::string::npos) << named << ": " << r.err;
  }
}

}  // namespace
}  // namespace nsg::test

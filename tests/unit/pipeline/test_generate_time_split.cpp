// splits.preset before-after on the e2e world captured over two days (scenes.capture_days 2):
// train tiles only from the scenes before the date, test tiles only from those after, the
// leakage figures in the manifest, and the config's relations named.
#include <gtest/gtest.h>

#include <map>

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

// scene name → its log's date_captured.
std::map<std::string, std::string> scene_dates(const fs::path& release) {
  std::map<std::string, std::string> log_date, out;
  for (const json& l : read_json(release / "v1.0-mini" / "log.json")) log_date[l["token"]] = l["date_captured"];
  for (const json& s : read_json(release / "v1.0-mini" / "scene.json")) out[s["name"]] = log_date.at(s["log_token"]);
  return out;
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
  const json& split = ds.manifest()["locations"][0]["time_split"];
  EXPECT_EQ(split["date"], second_day);
  EXPECT_EQ(split["scenes"]["train"], 3);
  EXPECT_EQ(split["scenes"]["test"], 2);
  const int64_t train = ds.manifest()["counts"]["train"]["tiles"], test = ds.manifest()["counts"]["test"]["tiles"];
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

// Whole-run progress of `generate`: off a terminal each stage ends with one plain
// log line carrying its totals, counted up front from the tables; --quiet prints none.
#include <gtest/gtest.h>

#include <algorithm>

#include "generate_fixture.h"
#include "nsg/core/strings.h"
#include "nsg/nuscenes/database.h"
#include "test_support.h"

namespace nsg::pipeline {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> without_quiet(std::vector<std::string> args) {
  args.erase(std::remove(args.begin(), args.end(), std::string("--quiet")), args.end());
  return args;
}

TEST(RunProgress, PlainStageSummariesOffATerminalAndNoneWhenQuiet) {
  const nuscenes::Database db = nuscenes::Database::load(test::e2e_release(), "v1.0-mini");
  size_t sweeps = 0, images = 0;
  for (const nuscenes::SampleData& sd : db.sample_data) {
    sweeps += db.channel(sd) == "LIDAR_TOP";
    images += sd.modality == nuscenes::Modality::kCamera && sd.is_key_frame;
  }
  const std::string location = db.log[0].location;

  test::TempDir tmp("run_progress");
  std::vector<std::string> args = without_quiet(test::e2e_generate_args(tmp / "loud"));
  args.insert(args.end(), {"--threads", "2"});
  const test::CommandResult loud = test::run_nsgraph(args);  // stderr is a pipe, not a tty
  ASSERT_EQ(loud.exit_code, 0) << loud.err;
  const nlohmann::json manifest = test::read_json(tmp / "loud/manifest.json");
  size_t tiles = 0;
  for (const auto& shard : manifest["shards"]) tiles += shard["tiles"].get<size_t>();
  ASSERT_GT(tiles, 0u);
  const std::string lidar = strprintf("lidar sweeps: %zu/%zu (100%%)", sweeps, sweeps);
  const std::string scenes = strprintf("%zu/%zu scenes", db.scene.size(), db.scene.size());
  const std::string camera = strprintf("camera images: %zu/%zu (100%%)", images, images);
  const std::string tile = strprintf("tiles %s: %zu/%zu (100%%)", location.c_str(), tiles, tiles);
  for (const std::string& s : {lidar, scenes, camera, tile, std::string("MB written")})
    EXPECT_NE(loud.err.find(s), std::string::npos) << "missing '" << s << "' in:\n" << loud.err;
  EXPECT_EQ(loud.err.find('\r'), std::string::npos) << "no in-place redraws off a terminal";
  // One final line per stage (a run this small ends before any 5 s interval line).
  EXPECT_EQ(loud.err.find(lidar), loud.err.rfind(lidar));
  EXPECT_EQ(loud.err.find(tile), loud.err.rfind(tile));

  std::vector<std::string> quiet_args = test::e2e_generate_args(tmp / "quiet");
  quiet_args.insert(quiet_args.end(), {"--threads", "2"});
  const test::CommandResult quiet = test::run_nsgraph(quiet_args);
  ASSERT_EQ(quiet.exit_code, 0) << quiet.err;
  for (const char* s : {"lidar sweeps", "camera images", "tiles ", "MB written"})
    EXPECT_EQ(quiet.err.find(s), std::string::npos) << s << " in:\n" << quiet.err;
  // Progress lines change no output byte.
  EXPECT_EQ(test::tree_hashes(tmp / "loud"), test::tree_hashes(tmp / "quiet"));
}

// The commands that read a whole dataset (seconds to minutes on a real one) report as
// generate does: off a terminal a final line with the totals from the manifest, no '\r';
// nothing under --quiet.
TEST(RunProgress, DatasetCommandsReportTheirTilesOffATerminal) {
  const fs::path ds = test::e2e_dataset();
  const nlohmann::json manifest = test::read_json(ds / "manifest.json");
  size_t tiles = 0, test_tiles = 0;
  std::string test_key;
  for (const auto& shard : manifest["shards"]) {
    tiles += shard["tiles"].get<size_t>();
    if (shard["split"] != "test") continue;
    test_tiles += shard["tiles"].get<size_t>();
    test_key = shard["first_key"];
  }
  const size_t shards = manifest["shards"].size();
  test::TempDir tmp("dataset_progress");
  // One empty graph of a test tile: the rest of the split is scored as missing.
  test::write_text(tmp / "sub.json",
                   R"({"schema_version": "1", "tiles": {")" + test_key + R"(": {"nodes": [], "edges": []}}})");
  struct Case {
    std::vector<std::string> args;
    std::string line;
  };
  const std::vector<Case> cases = {
      {{"stats", "--dataset", ds.string()}, strprintf("stats tiles: %zu/%zu (100%%)", tiles, tiles)},
      {{"validate", "--dataset", ds.string()}, strprintf("validate shards: %zu/%zu (100%%)", shards, shards)},
      {{"report", "--dataset", ds.string(), "--split", "test", "--out", (tmp / "report").string()},
       strprintf("report tiles: %zu/%zu (100%%)", test_tiles, test_tiles)},
      {{"score", "--ground-truth", ds.string(), "--submission", (tmp / "sub.json").string()},
       strprintf("score tiles: %zu/%zu (100%%)", test_tiles, test_tiles)},
      {{"preview", "--dataset", ds.string(), "--out", (tmp / "previews").string()},
       strprintf("preview shards: %zu/%zu (100%%)", shards, shards)},
      {{"preview", "--dataset", ds.string(), "--submission", (tmp / "sub.json").string(), "--out",
        (tmp / "overlay").string()},
       strprintf("preview scoring tiles: %zu/%zu (100%%)", test_tiles, test_tiles)},
  };
  for (const Case& c : cases) {
    const test::CommandResult loud = test::run_nsgraph(c.args);
    ASSERT_EQ(loud.exit_code, 0) << loud.err;
    EXPECT_NE(loud.err.find(c.line), std::string::npos) << "missing '" << c.line << "' in:\n" << loud.err;
    EXPECT_EQ(loud.err.find('\r'), std::string::npos) << loud.err;
    std::vector<std::string> quiet = c.args;
    quiet.insert(quiet.begin() + 1, "--quiet");
    const test::CommandResult q = test::run_nsgraph(quiet);
    ASSERT_EQ(q.exit_code, 0) << q.err;
    EXPECT_EQ(q.err.find(c.line.substr(0, c.line.find(':'))), std::string::npos) << q.err;
  }
}

}  // namespace
}  // namespace nsg::pipeline

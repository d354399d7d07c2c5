// End to end: `nsgraph generate` on a synthetic release carrying the real data's
// quirks — a map with every map-expansion defect of docs/nuscenes-input.md at once, a test split
// with empty instance / sample_annotation tables — completes (exit 0) and builds the lane
// graph from the good records; what the devkit cannot load either (truncated or missing
// sweeps, a --version folder that is not there) stops with exit 2 naming the file.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "nsg/graph/from_map.h"
#include "nsg/nuscenes/map_expansion.h"
#include "real_defects_fixture.h"
#include "test_support.h"

namespace nsg::nuscenes {
namespace {

namespace fs = std::filesystem;
using test::OJson;
using test::RealMapDefects;

const std::string kVersion = "v1.0-mini";
const std::string kLocation = "boston-seaport";

// The tiny synthetic release (samples/synth/tiny.json), made once per nsgraph build.
fs::path tiny_release() {
  const fs::path config = test::source_dir() / "samples/synth/tiny.json";
  return test::cached_folder("release_tiny_real_defects", test::nsgraph_build_key(), [&](const fs::path& dir) {
    const test::CommandResult r =
        test::run_nsgraph({"synth", "--quiet", "--config", config.string(), "--out", dir.string(), "--seed", "7"});
    if (r.exit_code != 0) throw std::runtime_error("synth tiny failed: " + r.err);
  });
}

// A copy of the tiny release made of symlinks; `own` replaces one by a real copy to edit.
class ReleaseCopy {
 public:
  ReleaseCopy() : dir_("real-defects-generate") {
    const fs::path source = fs::absolute(tiny_release());
    for (const auto& e : fs::recursive_directory_iterator(source)) {
      const fs::path to = root() / fs::relative(e.path(), source);
      if (e.is_directory()) {
        fs::create_directories(to);
      } else {
        fs::create_directories(to.parent_path());
        fs::create_symlink(e.path(), to);
      }
    }
  }
  fs::path root() const { return dir_.path() / "release"; }
  fs::path out(const std::string& name) const { return dir_.path() / name; }
  fs::path own(const std::string& rel) const {
    const fs::path p = root() / rel;
    const fs::path target = fs::read_symlink(p);
    fs::remove(p);
    fs::copy_file(target, p);
    return p;
  }
  fs::path map_file() const { return own("maps/expansion/" + kLocation + ".json"); }
  // The first LiDAR sweep file in name order (every sweep of the tiny release is used).
  std::string first_sweep() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(root() / "sweeps" / "LIDAR_TOP")) names.push_back(e.path().filename());
    std::sort(names.begin(), names.end());
    return "sweeps/LIDAR_TOP/" + names.at(0);
  }
  test::CommandResult generate(const std::string& out_name, std::vector<std::string> extra = {}) const {
    std::vector<std::string> args{"generate",   "--quiet",
                                  "--config",   (test::source_dir() / "tests/data/generate/e2e.json").string(),
                                  "--dataroot", root().string(),
                                  "--out",      out(out_name).string(),
                                  "--set",      "output.layout=folder"};
    args.insert(args.end(), extra.begin(), extra.end());
    return test::run_nsgraph(args);
  }

 private:
  test::TempDir dir_;
};

nlohmann::json lane_graph_of(const fs::path& out) {
  const nlohmann::json manifest = nlohmann::json::parse(test::read_text(out / "manifest.json"));
  return manifest.at("locations").at(0).at("lane_graph");
}

// counts.vehicle_px of every tile's meta.json; also the number of tiles.
std::pair<int64_t, size_t> vehicle_pixels(const fs::path& out) {
  int64_t px = 0;
  size_t tiles = 0;
  for (const auto& e : fs::recursive_directory_iterator(out / "tiles")) {
    if (e.path().filename().string().ends_with(".meta.json")) {
      px += nlohmann::json::parse(test::read_text(e.path()))["counts"]["vehicle_px"].get<int64_t>();
      ++tiles;
    }
  }
  return {px, tiles};
}

// Every file under tiles/ (path relative to it → bytes).
std::map<std::string, std::string> tile_files(const fs::path& out) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(out / "tiles"))
    if (e.is_regular_file()) files[fs::relative(e.path(), out).string()] = test::read_text(e.path());
  return files;
}

TEST(RealDefectsGenerate, MapWithEveryDefectGeneratesFromTheGoodRecords) {
  ReleaseCopy release;
  const test::CommandResult clean = release.generate("clean", {"--version", kVersion});
  ASSERT_EQ(clean.exit_code, 0) << clean.err;
  const nlohmann::json before = lane_graph_of(release.out("clean"));
  EXPECT_EQ(before["map_defects"], 0);

  const fs::path map_file = release.map_file();
  OJson m = test::read_json_file(map_file);
  test::add_real_map_defects(m);
  test::write_json_file(map_file, m);
  const test::CommandResult r = release.generate("defects", {"--version", kVersion});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json after = lane_graph_of(release.out("defects"));
  EXPECT_EQ(after["nodes"].get<size_t>(), before["nodes"].get<size_t>() + RealMapDefects::kIslandNodes);
  EXPECT_EQ(after["edges"].get<size_t>(), before["edges"].get<size_t>() + RealMapDefects::kIslandEdges);
  EXPECT_EQ(after["lanes"].get<size_t>(), before["lanes"].get<size_t>() + 4);
  // The manifest counts exactly the issues the library reports for this map.
  const MapExpansion map = load_map_expansion_file(map_file);
  Issues issues;
  (void)graph::build_lane_graph(map, {}, &issues);
  EXPECT_EQ(after["map_defects"].get<size_t>(), issues.size()) << issues.format();
  // And exactly what the fixture added (a null token or empty link is reported once per
  // table and field that holds it, whatever the number of records; the rest once each):
  const std::map<std::string, size_t> expected = {
      {"graph.dangling_connectivity", 2},    // ghost-out, ghost-in on the first lane
      {"map.empty_hole", 1},                 // the null-token polygon's hole
      {"map.empty_line", 1},                 // line-zero
      {"map.empty_link", 5},                 // ped_crossing, stop_line, road_segment links and more
      {"map.null_token", 5},                 // road_block and drivable_area polygon tokens and more
      {"map.self_intersecting_polygon", 1},  // the bow tie
  };
  std::map<std::string, size_t> found;
  for (const Issue& i : issues.items()) ++found[i.check];
  EXPECT_EQ(found, expected) << issues.format();
  EXPECT_EQ(after["map_defects"].get<size_t>(), 15u);
  // The tiles lie away from the added records: the same tiles as before, byte for byte.
  const auto clean_tiles = tile_files(release.out("clean")), defect_tiles = tile_files(release.out("defects"));
  EXPECT_GT(clean_tiles.size(), 0u);
  EXPECT_TRUE(clean_tiles == defect_tiles) << clean_tiles.size() << " vs " << defect_tiles.size() << " files";
  EXPECT_GT(vehicle_pixels(release.out("defects")).second, 0u);
}

// The test split ships empty instance and sample_annotation tables: the vehicle layer is
// then empty, or drawn from detections.
TEST(RealDefectsGenerate, EmptyAnnotationTablesLikeTheTestSplit) {
  ReleaseCopy release;
  const test::CommandResult clean = release.generate("clean", {"--version", kVersion});
  ASSERT_EQ(clean.exit_code, 0) << clean.err;
  test::write_text(release.own(kVersion + "/instance.json"), "[]");
  test::write_text(release.own(kVersion + "/sample_annotation.json"), "[]");
  const test::CommandResult r = release.generate("no-annotations", {"--version", kVersion});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto [px, tiles] = vehicle_pixels(release.out("no-annotations"));
  EXPECT_EQ(tiles, vehicle_pixels(release.out("clean")).second);
  EXPECT_GT(tiles, 0u);
  EXPECT_EQ(px, 0);
  const fs::path detections = release.root() / "detections" / "synthetic_detector.json";
  const test::CommandResult d =
      release.generate("detections", {"--version", kVersion, "--detections", detections.string()});
  ASSERT_EQ(d.exit_code, 0) << d.err;
  EXPECT_GT(vehicle_pixels(release.out("detections")).first, 0);
}

// The devkit cannot reshape a truncated sweep either: exit 2 naming the file.
TEST(RealDefectsGenerate, TruncatedSweepStopsNamingTheFile) {
  ReleaseCopy release;
  const std::string sweep = release.first_sweep();
  const fs::path file = release.own(sweep);
  fs::resize_file(file, fs::file_size(file) - 8);  // 5 504 floats: not whole points
  const test::CommandResult r = release.generate("out", {"--version", kVersion});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find(sweep), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("a multiple of 20 bytes"), std::string::npos) << r.err;
}

TEST(RealDefectsGenerate, MissingSweepStopsNamingTheFile) {
  ReleaseCopy release;
  const std::string sweep = release.first_sweep();
  fs::remove(release.root() / sweep);
  const test::CommandResult r = release.generate("out", {"--version", kVersion});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find(sweep), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("archive"), std::string::npos) << r.err;
}

// --version defaults to v1.0-trainval: name the release folders that exist instead.
TEST(RealDefectsGenerate, DefaultVersionNamesTheFoldersFound) {
  ReleaseCopy release;
  const test::CommandResult r = release.generate("out");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("no v1.0-trainval/ under " + release.root().string()), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("found: v1.0-mini (use --version v1.0-mini)"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace nsg::nuscenes

// "Whatever the official devkit loads, nsgraph loads": the map expansion defects
// of the real v1.3 maps (docs/nuscenes-input.md) load, are reported in MapExpansion::issues() naming
// the file and record, and only what the devkit refuses is refused. Through the reader and
// through `inspect centerlines` / `inspect graph`.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "nsg/core/error.h"
#include "nsg/nuscenes/map_expansion.h"
#include "real_defects_fixture.h"
#include "test_map_fixture.h"

namespace nsg::nuscenes {
namespace {

using test::OJson;
using test::RealMapDefects;

OJson small_map() { return OJson::parse(test::small_map_text()); }

OJson defect_map() {
  OJson m = small_map();
  test::add_real_map_defects(m);
  return m;
}

// The one issue of `check` whose subject contains `subject_part` (fails if not exactly one).
const Issue* find_issue(const Issues& issues, const std::string& check, const std::string& subject_part) {
  const Issue* found = nullptr;
  size_t n = 0;
  for (const Issue& i : issues.items()) {
    if (i.check == check && i.subject.find(subject_part) != std::string::npos) {
      found = &i;
      ++n;
    }
  }
  EXPECT_EQ(n, 1u) << check << " / " << subject_part << " in:\n" << issues.format();
  return n == 1 ? found : nullptr;
}

class RealMapDefectsTest : public ::testing::Test {
 protected:
  MapExpansion load(const OJson& m) {
    file_ = test::write_map(root_, m.dump(1));
    return load_map_expansion_file(file_);
  }
  test::TempDir root_{"real-map-defects"};
  std::filesystem::path file_;
};

TEST_F(RealMapDefectsTest, EveryDefectLoadsWithTheRecordsTheDevkitWouldHave) {
  const MapExpansion map = load(defect_map());
  // The null-token polygon is the 9th; every null polygon link resolves to it.
  ASSERT_EQ(map.polygons().size(), 12u);
  const MapIndex null_polygon = 8;
  EXPECT_EQ(map.polygons()[null_polygon].token, "");
  EXPECT_EQ(map.find(MapLayer::kPolygon, ""), null_polygon);
  ASSERT_EQ(map.road_blocks().size(), 1u);
  EXPECT_EQ(map.road_blocks()[0].polygon, null_polygon);
  ASSERT_EQ(map.drivable_areas().size(), 1u + RealMapDefects::kExtraDrivableAreas);
  EXPECT_EQ(map.drivable_areas()[0].polygons.size(), 3u);
  EXPECT_EQ(map.drivable_areas()[0].polygons.back(), null_polygon);
  EXPECT_EQ(map.drivable_areas().back().polygons, std::vector<MapIndex>{null_polygon});
  EXPECT_EQ(map.lanes()[2].polygon, null_polygon);  // island-a
  EXPECT_EQ(map.lane_connectors()[2].polygon, null_polygon);
  // "" links are kept as read; empty layers and zero poses are fine.
  EXPECT_EQ(map.ped_crossings()[0].road_segment_token, "");
  EXPECT_EQ(map.road_segments()[0].drivable_area_token, "");
  EXPECT_TRUE(map.carpark_areas().empty());
  EXPECT_EQ(map.size(MapLayer::kCarparkArea), 0u);
  EXPECT_EQ(map.traffic_lights()[0].pose.tx, 0.0);
  EXPECT_EQ(map.traffic_lights()[0].pose.tz, 2.5);
  EXPECT_TRUE(map.lines().back().nodes.empty());
  EXPECT_TRUE(map.polygons()[null_polygon].holes[0].nodes.empty());
  // Dangling connectivity is kept as read (the graph builder skips it).
  EXPECT_EQ(map.outgoing("lane-a"), (std::vector<std::string>{"conn-1", RealMapDefects::kGhostOut}));
  EXPECT_EQ(map.lanes().size(), 4u);
  EXPECT_EQ(map.lane_connectors().size(), 4u);
  EXPECT_EQ(map.get_arcline_path(RealMapDefects::kIslandC)[0].segment_length_m[1], RealMapDefects::kTinySegmentM);
}

TEST_F(RealMapDefectsTest, DefectsAreReportedNamingFileRecordAndCount) {
  const MapExpansion map = load(defect_map());
  const Issues& issues = map.issues();
  const std::string file = file_.string();
  // Null tokens: one issue per layer and key, naming the first record and the count.
  const Issue* own = find_issue(issues, "map.null_token", file + ": polygon #8");
  ASSERT_NE(own, nullptr);
  EXPECT_EQ(own->severity, Severity::kInfo);
  EXPECT_NE(own->message.find("key \"token\" is null"), std::string::npos) << own->message;
  EXPECT_NE(own->message.find(": 1 polygon record(s) (#8)"), std::string::npos) << own->message;
  const Issue* rb = find_issue(issues, "map.null_token", file + ": road_block 'rb-1'");
  ASSERT_NE(rb, nullptr);
  EXPECT_NE(rb->message.find("key \"polygon_token\""), std::string::npos);
  const Issue* da = find_issue(issues, "map.null_token", file + ": drivable_area 'da-1'");
  ASSERT_NE(da, nullptr);
  EXPECT_NE(da->message.find("301 drivable_area record(s) ('da-1', 'da-extra-0', 'da-extra-1', … 298 more)"),
            std::string::npos)
      << da->message;
  EXPECT_NE(find_issue(issues, "map.null_token", ": lane 'island-a'"), nullptr);
  EXPECT_NE(find_issue(issues, "map.null_token", ": lane_connector 'island-c'"), nullptr);
  // "" links.
  EXPECT_NE(find_issue(issues, "map.empty_link", ": ped_crossing 'pc-1'"), nullptr);
  const Issue* sl = find_issue(issues, "map.empty_link", ": stop_line 'sl-ped'");
  ASSERT_NE(sl, nullptr);
  EXPECT_NE(sl->message.find("key \"road_block_token\" is \"\""), std::string::npos);
  EXPECT_NE(sl->message.find("3 stop_line record(s)"), std::string::npos) << sl->message;
  EXPECT_NE(find_issue(issues, "map.empty_link", ": road_segment 'rs-1'"), nullptr);
  // Geometry: warnings.
  const Issue* lines = find_issue(issues, "map.empty_line", ": line 'line-empty'");
  ASSERT_NE(lines, nullptr);
  EXPECT_EQ(lines->severity, Severity::kWarning);
  EXPECT_NE(lines->message.find("2 line record(s) ('line-empty', 'line-zero')"), std::string::npos);
  EXPECT_NE(find_issue(issues, "map.empty_hole", ": polygon #8"), nullptr);
  EXPECT_EQ(issues.count_check("map.self_intersecting_polygon"), 1u) << issues.format();
  EXPECT_NE(find_issue(issues, "map.self_intersecting_polygon", ": polygon 'bowtie'"), nullptr);
  EXPECT_EQ(issues.count(Severity::kError), 0u);
}

TEST_F(RealMapDefectsTest, CleanFixtureReportsOnlyItsOwnQuirks) {
  const MapExpansion map = load(small_map());
  // small-map.json has one zero-node line and two "" stop_line.road_block_tokens.
  EXPECT_EQ(map.issues().size(), 2u) << map.issues().format();
  EXPECT_EQ(map.issues().count_check("map.empty_line"), 1u);
  EXPECT_EQ(map.issues().count_check("map.empty_link"), 1u);
}

// The devkit looks a null link up as None: without a null-token record that is a KeyError.
TEST_F(RealMapDefectsTest, NullLinkWithoutNullRecordIsRefusedLikeTheDevkit) {
  OJson m = small_map();
  m["road_block"][0]["polygon_token"] = nullptr;
  try {
    (void)load(m);
    FAIL() << "expected a DataError";
  } catch (const DataError& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.file(), file_.string());
    EXPECT_NE(what.find("road_block 'rb-1'"), std::string::npos) << what;
    EXPECT_NE(what.find("null or \"\", and no polygon record has a null token"), std::string::npos) << what;
  }
}

// drivable_area is never resolved by the devkit at load: a null entry with nothing to
// find is left out with a warning instead.
TEST_F(RealMapDefectsTest, NullDrivableEntryWithoutNullPolygonIsLeftOut) {
  OJson m = small_map();
  m["drivable_area"][0]["polygon_tokens"].push_back(nullptr);
  const MapExpansion map = load(m);
  EXPECT_EQ(map.drivable_areas()[0].polygon_tokens.size(), 3u);
  EXPECT_EQ(map.drivable_areas()[0].polygons.size(), 2u);
  const Issue* i = find_issue(map.issues(), "map.unresolved_null", ": drivable_area 'da-1'");
  ASSERT_NE(i, nullptr);
  EXPECT_EQ(i->severity, Severity::kWarning);
}

TEST_F(RealMapDefectsTest, WrongTypeTokenIsStillAParseError) {
  OJson m = small_map();
  m["polygon"][2]["token"] = 7;
  try {
    (void)load(m);
    FAIL() << "expected a ParseError";
  } catch (const ParseError& e) {
    EXPECT_NE(std::string(e.what()).find("polygon #2: key \"token\": expected a string (or null)"), std::string::npos)
        << e.what();
  }
}

// The devkit: version "1.3" or later by string comparison; no version counts as "1.0";
// a v1.1 file (no arcline_path_3 / connectivity) is refused for its version before its
// layers are read; a missing layer is a KeyError.
TEST_F(RealMapDefectsTest, VersionHandlingMatchesTheDevkit) {
  OJson m = small_map();
  EXPECT_EQ(load(m).version(), "1.3");
  m["version"] = "2.0";
  EXPECT_EQ(load(m).version(), "2.0");
  OJson v11 = small_map();
  v11["version"] = "1.1";
  v11.erase("arcline_path_3");
  v11.erase("connectivity");
  EXPECT_THROW(
      {
        try {
          (void)load(v11);
        } catch (const DataError& e) {
          EXPECT_NE(std::string(e.what()).find("got \"1.1\""), std::string::npos) << e.what();
          throw;
        }
      },
      DataError);
  OJson unversioned = small_map();
  unversioned.erase("version");
  try {
    (void)load(unversioned);
    FAIL() << "a map without version counts as 1.0";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("got \"1.0\""), std::string::npos) << e.what();
  }
  OJson no_arclines = small_map();
  no_arclines.erase("arcline_path_3");
  try {
    (void)load(no_arclines);
    FAIL() << "a v1.3 map without arcline_path_3";
  } catch (const ParseError& e) {
    EXPECT_NE(std::string(e.what()).find("arcline_path_3"), std::string::npos) << e.what();
  }
  OJson no_carparks = small_map();
  no_carparks.erase("carpark_area");
  EXPECT_THROW((void)load(no_carparks), ParseError);
}

// ---- the CLI ---------------------------------------------------------------------------

test::CommandResult run_inspect(const test::TempDir& root, const std::string& what,
                                std::vector<std::string> extra = {}) {
  std::vector<std::string> args{"inspect", what, "--dataroot", root.path().string(), "--location", "boston-seaport"};
  args.insert(args.end(), extra.begin(), extra.end());
  return test::run_nsgraph(args);
}

TEST_F(RealMapDefectsTest, InspectCenterlinesLoadsAndReportsOnStderr) {
  (void)load(defect_map());
  const test::CommandResult r = run_inspect(root_, "centerlines");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["centerlines"].size(), 8u);  // 4 lanes, 4 connectors
  EXPECT_EQ(j["centerlines"][2]["token"], RealMapDefects::kIslandA);
  EXPECT_EQ(j["centerlines"][2]["poses"].size(), 4u);  // 6 m at 2 m
  const nlohmann::json edges = j["edges"];
  EXPECT_EQ(edges, nlohmann::json::parse(R"([["lane-a", "conn-1"], ["conn-1", "lane-b"],
      ["island-a", "island-b"], ["island-b", "island-c"], ["island-c", "island-d"]])"));
  EXPECT_NE(r.err.find("map.null_token " + file_.string() + ": polygon #8"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("map.dangling_connectivity " + file_.string() + ": connectivity 'lane-a'"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("'ghost-out'"), std::string::npos) << r.err;
}

TEST_F(RealMapDefectsTest, InspectGraphBuildsTheGoodRecordsAndListsTheDefects) {
  (void)load(small_map());
  const test::CommandResult clean = run_inspect(root_, "graph");
  ASSERT_EQ(clean.exit_code, 0) << clean.err;
  const nlohmann::json c = nlohmann::json::parse(clean.out);
  (void)load(defect_map());
  const test::CommandResult r = run_inspect(root_, "graph");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["lanes"], 4);
  EXPECT_EQ(j["lane_connectors"], 4);
  EXPECT_EQ(j["nodes"].get<size_t>(), c["nodes"].get<size_t>() + RealMapDefects::kIslandNodes);
  EXPECT_EQ(j["edges"].get<size_t>(), c["edges"].get<size_t>() + RealMapDefects::kIslandEdges);
  EXPECT_LE(j["max_edge_length_m"].get<double>(), 2.0 + 1e-9);
  EXPECT_EQ(j["defect_counts"]["graph.dangling_connectivity"], 2);
  EXPECT_EQ(j["defect_counts"]["map.self_intersecting_polygon"], 1);
  EXPECT_EQ(j["defect_counts"]["map.null_token"], 5);             // polygon, road_block, drivable_area, lane, connector
  EXPECT_FALSE(j["defect_counts"].contains("graph.ends_apart"));  // the 3 mm gap is joined
  bool named = false;
  for (const auto& d : j["defects"]) {
    if (d["check"] == "map.null_token" && d["token"] == file_.string() + ": road_block 'rb-1'") named = true;
  }
  EXPECT_TRUE(named) << j["defects"].dump(1);
  // --strict turns the map's warnings (zero-node lines, bow tie, dangling links) into exit 2.
  const test::CommandResult strict = run_inspect(root_, "graph", {"--strict"});
  EXPECT_EQ(strict.exit_code, 2);
  EXPECT_NE(strict.err.find("boston-seaport.json"), std::string::npos) << strict.err;
}

}  // namespace
}  // namespace nsg::nuscenes

// The change labels of a map-update dataset (nsg/graph/map_changes.h) on hand-made versions of
// the real key frame's stand-in map: a lane shifted 0.5 m is moved, one whose divider
// segments change type is retyped, a lane in one version only is added or removed, the same
// map twice is unchanged; and the labels land on a clipped graph's edges by token.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "nsg/core/files.h"
#include "nsg/graph/map_changes.h"
#include "test_support.h"

namespace nsg::graph {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

json stand_in() {
  return json::parse(
      read_file(test::source_dir() / "tests/data/real/scene-0061-keyframe/maps/expansion/singapore-onenorth.json"));
}

nuscenes::MapExpansion load(const test::TempDir& dir, const std::string& name, const json& doc) {
  fs::create_directories(dir / name);
  test::write_text(dir / name / "singapore-onenorth.json", doc.dump());
  return nuscenes::load_map_expansion_file(dir / name / "singapore-onenorth.json");
}

TEST(MapChanges, EachLabelFromTwoVersionsOfAMap) {
  test::TempDir dir("map-changes");
  const json prior = stand_in();
  const std::string lane = prior["lane"][0]["token"];
  const nuscenes::MapExpansion before = load(dir, "prior", prior);

  const auto same = lane_changes_between(before, load(dir, "same", prior));
  ASSERT_EQ(same.size(), 1u);
  EXPECT_EQ(same.at(lane), MapChange::kUnchanged);

  json moved = prior;
  for (const char* end : {"start_pose", "end_pose"}) moved["arcline_path_3"][lane][0][end][1] = 1181.390380859375;
  EXPECT_EQ(lane_changes_between(before, load(dir, "moved", moved)).at(lane), MapChange::kMoved);
  json nudged = prior;  // within the tolerance: the same lane
  nudged["arcline_path_3"][lane][0]["start_pose"][1] = 1180.890380859375 + 0.5 * kMovedToleranceM;
  EXPECT_EQ(lane_changes_between(before, load(dir, "nudged", nudged)).at(lane), MapChange::kUnchanged);

  json typed_before = prior, typed_after = prior;
  const json node = prior["node"][2]["token"];
  typed_before["lane"][0]["left_lane_divider_segments"] = {
      {{"node_token", node}, {"segment_type", "SINGLE_DASHED_WHITE"}}};
  typed_after["lane"][0]["left_lane_divider_segments"] = {
      {{"node_token", node}, {"segment_type", "SINGLE_SOLID_WHITE"}}};
  EXPECT_EQ(
      lane_changes_between(load(dir, "typed-before", typed_before), load(dir, "typed-after", typed_after)).at(lane),
      MapChange::kRetyped);

  const nuscenes::MapExpansion other = load(
      dir, "other", json::parse(read_file(test::source_dir() / "tests/data/real/road-ahead/singapore-onenorth.json")));
  const std::string new_lane = other.lanes().at(0).token;
  const auto swapped = lane_changes_between(before, other);
  EXPECT_EQ(swapped.at(lane), MapChange::kRemoved);
  EXPECT_EQ(swapped.at(new_lane), MapChange::kAdded);

  TileGraph g;
  g.nodes = {{0, 0, 0, 0, 0, Junction::kNone}, {1, 1, 0, 1, 0, Junction::kNone}};
  g.edges = {{0, 1, lane}, {0, 1, new_lane}, {0, 1, "not-in-either"}};
  label_map_changes(g, swapped);
  EXPECT_EQ(g.edges[0].change, MapChange::kRemoved);
  EXPECT_EQ(g.edges[1].change, MapChange::kAdded);
  EXPECT_EQ(g.edges[2].change, MapChange::kNone);
  for (const MapChange c :
       {MapChange::kUnchanged, MapChange::kAdded, MapChange::kRemoved, MapChange::kMoved, MapChange::kRetyped}) {
    MapChange back = MapChange::kNone;
    EXPECT_TRUE(map_change_from_name(map_change_name(c), &back));
    EXPECT_EQ(back, c);
  }
  MapChange none = MapChange::kNone;
  EXPECT_FALSE(map_change_from_name("teleported", &none));
}

}  // namespace
}  // namespace nsg::graph

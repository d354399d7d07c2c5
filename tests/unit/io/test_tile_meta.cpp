// io::tile_meta_from_json: every field of a tile's meta.json checked, each defect named by
// its JSON path (stats and the report read tiles only through it).
#include <gtest/gtest.h>

#include "nsg/core/error.h"
#include "nsg/io/tile_meta.h"

namespace nsg::io {
namespace {

nlohmann::json valid_meta() {
  return nlohmann::json::parse(R"({
    "schema_version": "1", "key": "boston-seaport-test-000000", "location": "boston-seaport",
    "split": "test", "region": "test-0", "bounds_m": [100.0, 200.0, 151.2, 251.2],
    "resolution_m": 0.2, "size_px": 256,
    "coverage": {"lidar": 0.5, "rgb": 0.25, "semantic": 0.25},
    "counts": {"nodes": 10, "edges": 9, "vehicle_px": 100}, "scenes": ["scene-0001"]})");
}

// The JSON path the reader names for `doc`, or "" when it is accepted.
std::string refused_at(const nlohmann::json& doc) {
  try {
    tile_meta_from_json(doc, "t.meta.json");
    return "";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), "t.meta.json");
    return e.record();
  }
}

TEST(TileMeta, ReadsEveryField) {
  const TileMeta m = tile_meta_from_json(valid_meta(), "t.meta.json");
  EXPECT_EQ(m.location, "boston-seaport");
  EXPECT_EQ(m.split, "test");
  EXPECT_EQ(m.size_px, 256);
  EXPECT_DOUBLE_EQ(m.bounds_m[2], 151.2);
  EXPECT_EQ(m.vehicle_px, 100);
  EXPECT_EQ(m.scenes, std::vector<std::string>{"scene-0001"});
}

TEST(TileMeta, EachDefectIsNamedByItsPath) {
  const std::vector<std::pair<std::string, std::function<void(nlohmann::json&)>>> cases = {
      {"/bounds_m", [](nlohmann::json& j) { j["bounds_m"] = nlohmann::json::array(); }},
      {"/bounds_m",
       [](nlohmann::json& j) {
         j["bounds_m"] = {151.2, 200.0, 100.0, 251.2};
       }},
      {"/bounds_m/1", [](nlohmann::json& j) { j["bounds_m"][1] = 1e300; }},
      {"/size_px", [](nlohmann::json& j) { j["size_px"] = 20000; }},
      {"/size_px", [](nlohmann::json& j) { j["size_px"] = 0; }},
      {"/resolution_m", [](nlohmann::json& j) { j["resolution_m"] = 0; }},
      {"/split", [](nlohmann::json& j) { j["split"] = 3; }},
      {"/split", [](nlohmann::json& j) { j["split"] = "tset"; }},
      {"/counts", [](nlohmann::json& j) { j.erase("counts"); }},
      {"/counts/vehicle_px", [](nlohmann::json& j) { j["counts"]["vehicle_px"] = 256 * 256 + 1; }},
      {"/counts/nodes", [](nlohmann::json& j) { j["counts"]["nodes"] = -1; }},
      {"/coverage/rgb", [](nlohmann::json& j) { j["coverage"]["rgb"] = 1.5; }},
      {"/scenes/0", [](nlohmann::json& j) { j["scenes"] = {1}; }},
      {"/location", [](nlohmann::json& j) { j.erase("location"); }},
  };
  EXPECT_EQ(refused_at(valid_meta()), "");
  for (const auto& [path, edit] : cases) {
    nlohmann::json doc = valid_meta();
    edit(doc);
    EXPECT_EQ(refused_at(doc), path) << doc.dump();
  }
  EXPECT_THROW(tile_meta_from_json(nlohmann::json::array(), "t.meta.json"), ParseError);
}

}  // namespace
}  // namespace nsg::io

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <sstream>

#include "graph_fixtures.h"
#include "nsg/geometry/georef.h"
#include "nsg/graph/geojson.h"

namespace nsg::graph {
namespace {

TEST(GeoJson, EdgesRoundTripToMapMetresWithinOneMillimetre) {
  // Shift the T-junction into the map (y > 0 everywhere) near Boston's far corner.
  std::vector<LaneSource> map = test::t_junction();
  for (LaneSource& s : map)
    for (geometry::ArclinePath& p : s.paths) {
      p.start_pose.x += 2900;
      p.start_pose.y += 2050;
    }
  const LaneGraph g = build_lane_graph(map, {}, nullptr);
  std::ostringstream text;
  write_geojson(g, "boston-seaport", text);
  const nlohmann::json doc = nlohmann::json::parse(text.str());
  ASSERT_EQ(doc["type"], "FeatureCollection");
  ASSERT_EQ(doc["features"].size(), g.edges.size());
  const geometry::AzimuthalProjection projection("boston-seaport");
  for (size_t e = 0; e < g.edges.size(); ++e) {
    const nlohmann::json& f = doc["features"][e];
    EXPECT_EQ(f["properties"]["lane_token"], g.lanes[g.edges[e].lane].token);
    const auto& coords = f["geometry"]["coordinates"];
    ASSERT_EQ(coords.size(), 2u);
    for (int end = 0; end < 2; ++end) {
      const Node& n = g.nodes[end == 0 ? g.edges[e].source : g.edges[e].target];
      const auto xy = projection.to_map(coords[end][0].get<double>(), coords[end][1].get<double>());
      EXPECT_NEAR(xy[0], n.x_m, 1e-3);
      EXPECT_NEAR(xy[1], n.y_m, 1e-3);
      // Same answer as the devkit's own formula.
      const geometry::LonLat devkit = geometry::map_to_lonlat("boston-seaport", n.x_m, n.y_m);
      EXPECT_NEAR(coords[end][0].get<double>(), devkit.lon_deg, 1e-9);
      EXPECT_NEAR(coords[end][1].get<double>(), devkit.lat_deg, 1e-9);
    }
  }
  // Lon/lat order: Boston is west of Greenwich and north of the equator.
  EXPECT_LT(doc["features"][0]["geometry"]["coordinates"][0][0].get<double>(), -70.0);
  EXPECT_GT(doc["features"][0]["geometry"]["coordinates"][0][1].get<double>(), 42.0);
}

// bearing_deg is in [0, 360): a heading a hair west of north rounds to 0, not 360.
TEST(GeoJson, BearingStaysBelow360AfterRounding) {
  LaneGraph g;
  g.nodes = {{2900.0, 2050.0}, {2900.0 - 1e-5, 2060.0}, {2910.0, 2050.0}, {2900.0, 2040.0}, {2890.0, 2050.0}};
  g.lanes = {{"lane", false, 10.0, {}, {}}};
  g.edges = {{0, 1, 0}, {0, 2, 0}, {0, 3, 0}, {0, 4, 0}};
  std::ostringstream text;
  write_geojson(g, "boston-seaport", text);
  const nlohmann::json doc = nlohmann::json::parse(text.str());
  std::vector<double> bearings;
  for (const nlohmann::json& f : doc["features"]) bearings.push_back(f["properties"]["bearing_deg"].get<double>());
  EXPECT_EQ(bearings, (std::vector<double>{0.0, 90.0, 180.0, 270.0}));
  EXPECT_EQ(text.str().find("-0"), std::string::npos);
}

}  // namespace
}  // namespace nsg::graph

// Training targets from a hand-made graph, and LaneDirNet's label space and the paper's
// orientation rule.
#include <cmath>

#include <gtest/gtest.h>

#include "nsg/model/direction.h"
#include "nsg/model/targets.h"

namespace {

using namespace nsg::model;
using VoteArray = std::array<float, kDirectionClasses>;
using Vec = std::array<double, 2>;

constexpr double kPi = M_PI;

nsg::metrics::Graph one_edge(double u0, double v0, double u1, double v1) {
  nsg::metrics::Graph g;
  g.nodes = {{u0, v0}, {u1, v1}};
  g.edges = {{0, 1}};
  return g;
}

TEST(ModelTargets, DistanceAndAngleOfAHorizontalEdge) {
  const TileTargets east = compute_targets(one_edge(20, 64, 100, 64), 128, 30.0);
  const TileTargets west = compute_targets(one_edge(100, 64, 20, 64), 128, 30.0);
  ASSERT_EQ(east.distance_px.size(), cv::Size(128, 128));
  ASSERT_EQ(east.distance_px.type(), CV_32F);
  ASSERT_EQ(east.angle_rad.type(), CV_32F);
  for (int v = 40; v <= 90; ++v) {
    for (int u : {20, 33, 60, 99}) {
      SCOPED_TRACE(::testing::Message() << "u " << u << " v " << v);
      EXPECT_NEAR(east.distance_px.at<float>(v, u), std::abs(v - 64), 1e-4);
      EXPECT_NEAR(west.distance_px.at<float>(v, u), std::abs(v - 64), 1e-4);
      EXPECT_NEAR(east.angle_rad.at<float>(v, u), 0.0, 1e-6);
      EXPECT_NEAR(west.angle_rad.at<float>(v, u), kPi, 1e-6);
    }
  }
  // Beyond an end the distance is to the end point.
  EXPECT_NEAR(east.distance_px.at<float>(64, 10), 10.0, 1e-4);
  EXPECT_NEAR(east.distance_px.at<float>(70, 108), 10.0, 1e-4);  // (8, 6) from (100, 64)
  // Beyond the radius: the radius itself and no angle.
  for (int v : {0, 20, 33, 95, 127}) {
    EXPECT_EQ(east.distance_px.at<float>(v, 60), 30.0f) << v;
    EXPECT_TRUE(std::isnan(east.angle_rad.at<float>(v, 60))) << v;
  }
}

TEST(ModelTargets, NearestOfTwoEdgesAndNorthward) {
  // A northward edge at u = 30 and a southward one at u = 90: each pixel takes its
  // nearest edge's direction.
  nsg::metrics::Graph g;
  g.nodes = {{30, 120}, {30, 8}, {90, 8}, {90, 120}};
  g.edges = {{0, 1}, {2, 3}};
  const TileTargets t = compute_targets(g, 128, 40.0);
  EXPECT_NEAR(t.angle_rad.at<float>(64, 40), kPi / 2, 1e-6);
  EXPECT_NEAR(t.distance_px.at<float>(64, 40), 10.0, 1e-4);
  EXPECT_NEAR(t.angle_rad.at<float>(64, 70), 3 * kPi / 2, 1e-6);
  EXPECT_NEAR(t.distance_px.at<float>(64, 70), 20.0, 1e-4);
}

TEST(ModelTargets, EmptyGraphIsAllBackground) {
  const TileTargets t = compute_targets(nsg::metrics::Graph{}, 64, 12.0);
  EXPECT_EQ(cv::countNonZero(t.distance_px != 12.0f), 0);
  EXPECT_EQ(cv::countNonZero(t.angle_rad == t.angle_rad), 0);  // NaN != NaN everywhere
}

TEST(ModelDirection, BinsRoundTripAndWrap) {
  EXPECT_EQ(kDirectionClasses, 19);
  for (int k = 0; k < kDirectionBins; ++k) {
    EXPECT_EQ(direction_bin(bin_centre_rad(k)), k);
    EXPECT_NEAR(bin_centre_rad(k), (k + 0.5) * 2 * kPi / 18, 1e-12);
    // Bin edges: the lower edge belongs to the bin.
    EXPECT_EQ(direction_bin(k * 2 * kPi / 18 + 1e-9), k);
  }
  EXPECT_EQ(direction_bin(0.0), 0);
  EXPECT_EQ(direction_bin(-0.1), 17);
  EXPECT_EQ(direction_bin(2 * kPi), 0);
  EXPECT_EQ(direction_bin(2 * kPi - 1e-12), 17);
  EXPECT_EQ(direction_bin(4 * kPi + 0.1), 0);
  EXPECT_EQ(direction_bin(-2 * kPi + kPi / 2), 4);  // north
  EXPECT_EQ(direction_bin(kPi + 1e-9), 9);          // west: just above 180°, bin 9's lower edge
  EXPECT_EQ(direction_bin(kPi - 1e-9), 8);
}

TEST(ModelDirection, MapAngleOfPixelSteps) {
  EXPECT_NEAR(map_angle(1, 0), 0.0, 1e-12);          // east
  EXPECT_NEAR(map_angle(0, -1), kPi / 2, 1e-12);     // up the image = north
  EXPECT_NEAR(map_angle(-1, 0), kPi, 1e-12);         // west
  EXPECT_NEAR(map_angle(0, 1), 3 * kPi / 2, 1e-12);  // south
  EXPECT_NEAR(map_angle(1, -1), kPi / 4, 1e-12);     // north-east
  EXPECT_NEAR(map_angle(1, 1e-12), 2 * kPi, 1e-9);   // just south of east: in [0, 2π)
  EXPECT_LT(map_angle(1, 1e-12), 2 * kPi);
}

Vec unit(const Vec& v) {
  const double n = std::hypot(v[0], v[1]);
  return {v[0] / n, v[1] / n};
}

TEST(ModelDirection, MeanDirectionFromVotes) {
  VoteArray east{};
  east[0] = 7;  // 0°–20°, centre 10°
  const Vec e = unit(mean_direction_px(east));
  EXPECT_NEAR(e[0], std::cos(kPi / 18), 1e-9);
  EXPECT_NEAR(e[1], -std::sin(kPi / 18), 1e-9);  // map north = −v
  EXPECT_NEAR(std::hypot(mean_direction_px(east)[0], mean_direction_px(east)[1]), 7.0, 1e-9);

  VoteArray north{};
  north[4] = 5;  // centre 90°
  const Vec n = mean_direction_px(north);
  EXPECT_NEAR(n[0], 0.0, 1e-9);
  EXPECT_NEAR(n[1], -5.0, 1e-9);

  VoteArray around_north{};
  around_north[3] = 3;  // 70°
  around_north[5] = 3;  // 110°
  const Vec an = unit(mean_direction_px(around_north));
  EXPECT_NEAR(an[0], 0.0, 1e-9);
  EXPECT_NEAR(an[1], -1.0, 1e-9);

  VoteArray exact_east{};
  exact_east[0] = 4;
  exact_east[17] = 4;  // 350°
  const Vec ee = unit(mean_direction_px(exact_east));
  EXPECT_NEAR(ee[0], 1.0, 1e-9);
  EXPECT_NEAR(ee[1], 0.0, 1e-9);

  VoteArray background{};
  background[kBackgroundClass] = 40;
  EXPECT_EQ(mean_direction_px(background), (Vec{0.0, 0.0}));
  // Background votes do not pull a lane's direction.
  VoteArray mixed = north;
  mixed[kBackgroundClass] = 100;
  EXPECT_EQ(mean_direction_px(mixed), mean_direction_px(north));
}

TEST(ModelDirection, OrientRule) {
  const Vec a{10, 50}, b{20, 50};  // a → b points east
  VoteArray east_votes{}, west_votes{}, background{};
  east_votes[0] = east_votes[17] = 5;
  west_votes[8] = west_votes[9] = 5;
  background[kBackgroundClass] = 10;
  const Vec east = mean_direction_px(east_votes), west = mean_direction_px(west_votes);
  EXPECT_TRUE(orient_a_to_b(a, b, east, east));
  EXPECT_FALSE(orient_a_to_b(a, b, west, west));  // against the votes: flipped to b → a
  EXPECT_FALSE(orient_a_to_b(b, a, east, east));
  EXPECT_TRUE(orient_a_to_b(b, a, west, west));

  // VoteArray split between the anchors: the larger sum wins.
  VoteArray strong_east{}, weak_west{};
  strong_east[0] = strong_east[17] = 9;
  weak_west[8] = weak_west[9] = 2;
  EXPECT_TRUE(orient_a_to_b(a, b, mean_direction_px(strong_east), mean_direction_px(weak_west)));
  EXPECT_TRUE(orient_a_to_b(a, b, mean_direction_px(weak_west), mean_direction_px(strong_east)));
  EXPECT_FALSE(orient_a_to_b(b, a, mean_direction_px(weak_west), mean_direction_px(strong_east)));
  // Split within one anchor's votes: 7 west-ish against 3 east-ish.
  VoteArray split{};
  split[9] = 7;
  split[0] = 3;
  EXPECT_FALSE(orient_a_to_b(a, b, mean_direction_px(split), mean_direction_px(background)));

  // No direction evidence keeps a → b.
  const Vec none = mean_direction_px(background);
  EXPECT_TRUE(orient_a_to_b(a, b, none, none));
  EXPECT_TRUE(orient_a_to_b(b, a, none, none));

  // A diagonal edge (towards the south-east) against votes for north-west-ish travel.
  VoteArray northwest{};
  northwest[6] = 4;  // 130°
  EXPECT_FALSE(orient_a_to_b({10, 10}, {20, 20}, mean_direction_px(northwest), mean_direction_px(northwest)));
  // A perpendicular edge (north) with an exactly eastward mean: dot product 0 → a → b.
  EXPECT_TRUE(orient_a_to_b({10, 20}, {10, 10}, Vec{1, 0}, Vec{0, 0}));
  EXPECT_TRUE(orient_a_to_b({10, 10}, {10, 20}, Vec{1, 0}, Vec{0, 0}));
}

}  // namespace

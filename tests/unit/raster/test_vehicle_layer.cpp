#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "nsg/raster/vehicle_layer.h"

namespace nsg::raster {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(VehicleLayer, HeadingIsClockwiseBearingFromNorth) {
  EXPECT_NEAR(heading_fraction(kPi / 2), 0.0, 1e-12);   // north
  EXPECT_NEAR(heading_fraction(0.0), 0.25, 1e-12);      // east
  EXPECT_NEAR(heading_fraction(-kPi / 2), 0.5, 1e-12);  // south
  EXPECT_NEAR(heading_fraction(kPi), 0.75, 1e-12);      // west
  // Just west of north wraps to just below 1, never to 1 itself.
  EXPECT_NEAR(heading_fraction(kPi / 2 + 1e-15), 1.0, 1e-9);
  EXPECT_LT(heading_fraction(kPi / 2 + 1e-17), 1.0);
}

TEST(VehicleLayer, FootprintFilledWithHeadingAndEmptyElsewhere) {
  VehicleLayer layer;
  // A 4.6 × 1.8 m car heading north-east centred at (50.1, 60.1).
  layer.add_box({50.1, 60.1, kPi / 4, 4.6, 1.8, 1.0, 0});
  size_t filled = 0;
  layer.cells().for_each([&](CellIndex c, const VehicleCell& v) {
    const double x = (c.col + 0.5) * 0.2 - 50.1, y = (c.row + 0.5) * 0.2 - 60.1;
    const double along = (x + y) / std::sqrt(2.0), across = (y - x) / std::sqrt(2.0);
    const bool inside = std::abs(along) <= 2.3 && std::abs(across) <= 0.9;
    if (inside) {
      EXPECT_NEAR(v.heading, 0.125, 1.0 / 360);
      ++filled;
    } else {
      EXPECT_EQ(v.heading, -1.0f);
    }
  });
  EXPECT_NEAR(static_cast<double>(filled), 4.6 * 1.8 / 0.04, 12.0);
}

TEST(VehicleLayer, OverlapsKeepHighestScoreThenLatest) {
  VehicleLayer a;
  a.add_box({10, 10, 0, 4, 2, 0.4, 1});
  a.add_box({10, 10, kPi / 2, 4, 2, 0.9, 0});  // higher score wins though older
  const VehicleCell* v = a.cells().find(cell_of(10.05, 10.05, 0.2));
  ASSERT_NE(v, nullptr);
  EXPECT_NEAR(v->heading, 0.0, 1e-6);
  VehicleLayer b;
  b.add_box({10, 10, 0, 4, 2, 1.0, 5});
  b.add_box({10, 10, kPi, 4, 2, 1.0, 9});  // same score: latest wins
  EXPECT_NEAR(b.cells().find(cell_of(10.05, 10.05, 0.2))->heading, 0.75, 1e-6);
  // Merging is order independent.
  VehicleLayer ab, ba;
  ab.merge(a);
  ab.merge(b);
  ba.merge(b);
  ba.merge(a);
  EXPECT_EQ(ab.cells().find(cell_of(10.05, 10.05, 0.2))->heading, ba.cells().find(cell_of(10.05, 10.05, 0.2))->heading);
}

}  // namespace
}  // namespace nsg::raster

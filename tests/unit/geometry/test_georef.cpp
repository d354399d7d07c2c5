// Georeferencing: the devkit's spherical formula, GeographicLib's azimuthal-equidistant
// projection, and the PROJ string, on the four locations.
#include <gtest/gtest.h>

#include <cmath>

#include "nsg/core/error.h"
#include "nsg/geometry/georef.h"

namespace nsg::geometry {
namespace {

TEST(Georef, FourLocationsWithOriginsAndCanvas) {
  ASSERT_EQ(known_locations().size(), 4u);
  const LocationInfo& boston = location_info("boston-seaport");
  EXPECT_EQ(boston.origin_lat_deg, 42.336849169438615);
  EXPECT_EQ(boston.origin_lon_deg, -71.05785369873047);
  EXPECT_EQ(boston.canvas_width_m, 2979.5);
  EXPECT_EQ(boston.canvas_height_m, 2118.1);
  const LocationInfo& onenorth = location_info("singapore-onenorth");
  EXPECT_EQ(onenorth.canvas_width_m, 1585.6);
  EXPECT_EQ(onenorth.canvas_height_m, 2025.0);
  EXPECT_EQ(location_info("singapore-hollandvillage").origin_lat_deg, 1.2993652317780957);
  EXPECT_EQ(location_info("singapore-queenstown").origin_lon_deg, 103.76741409301758);
  EXPECT_EQ(location_info("singapore-queenstown").canvas_height_m, 3687.1);
  EXPECT_TRUE(is_known_location("singapore-hollandvillage"));
  EXPECT_FALSE(is_known_location("boston"));
}

TEST(Georef, UnknownLocationIsAConfigErrorNamingIt) {
  try {
    (void)location_info("singapore-newton");
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("singapore-newton"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("boston-seaport"), std::string::npos);
  }
  EXPECT_THROW(map_to_lonlat("Boston-Seaport", 1, 1), ConfigError);
  EXPECT_THROW(aeqd_proj_string(""), ConfigError);
  EXPECT_THROW(AzimuthalProjection("mars"), ConfigError);
}

// Values printed by the devkit's own get_coordinate(...) in CPython (same libm).
TEST(Georef, DevkitFormulaMatchesPythonValues) {
  const LonLat a = map_to_lonlat("boston-seaport", 100, 200);
  EXPECT_NEAR(a.lat_deg, 42.33864579359046, 1e-13);
  EXPECT_NEAR(a.lon_deg, -71.0566384075275, 1e-13);
  const LonLat b = map_to_lonlat("boston-seaport", 2900, 2100);
  EXPECT_NEAR(b.lat_deg, 42.35570839215996, 1e-13);
  EXPECT_NEAR(b.lon_deg, -71.02260068623912, 1e-13);
  const LonLat c = map_to_lonlat("singapore-onenorth", 800.5, 1500.25);
  EXPECT_NEAR(c.lat_deg, 1.3016870517413042, 1e-13);
  EXPECT_NEAR(c.lon_deg, 103.79194476205869, 1e-13);
  const LonLat origin = map_to_lonlat("singapore-queenstown", 0.0, 1e-9);
  EXPECT_NEAR(origin.lat_deg, 1.2782562240223188, 1e-12);
  EXPECT_NEAR(origin.lon_deg, 103.76741409301758, 1e-12);
}

TEST(Georef, GeographicLibAgreesWithDevkitForPositiveY) {
  for (const LocationInfo& loc : known_locations()) {
    const AzimuthalProjection proj(loc.name);
    for (double fx : {0.0, 0.01, 0.3, 0.77, 1.0}) {
      for (double fy : {0.001, 0.2, 0.5, 1.0}) {
        const double x = fx * loc.canvas_width_m;
        const double y = fy * loc.canvas_height_m;
        const LonLat devkit = map_to_lonlat(loc.name, x, y);
        const LonLat glib = proj.to_lonlat(x, y);
        EXPECT_NEAR(devkit.lat_deg, glib.lat_deg, 1e-10) << loc.name << " " << x << "," << y;
        EXPECT_NEAR(devkit.lon_deg, glib.lon_deg, 1e-10) << loc.name << " " << x << "," << y;
      }
    }
  }
}

TEST(Georef, NonPositiveYContinuesTheProjection) {
  const AzimuthalProjection proj("boston-seaport");
  for (auto [x, y] : {std::pair{150.0, 0.0}, {-40.0, -300.0}, {0.0, -10.0}}) {
    const LonLat devkit = map_to_lonlat("boston-seaport", x, y);
    const LonLat glib = proj.to_lonlat(x, y);
    EXPECT_NEAR(devkit.lat_deg, glib.lat_deg, 1e-10);
    EXPECT_NEAR(devkit.lon_deg, glib.lon_deg, 1e-10);
  }
}

TEST(Georef, ForwardReverseRoundTrip) {
  for (const LocationInfo& loc : known_locations()) {
    const AzimuthalProjection proj(loc.name);
    for (auto [x, y] : {std::pair{0.0, 0.0},
                        {12.5, 3000.0},
                        {loc.canvas_width_m, loc.canvas_height_m},
                        {-100.0, -250.0},
                        {1234.567, 89.0}}) {
      const LonLat ll = proj.to_lonlat(x, y);
      const std::array<double, 2> back = proj.to_map(ll.lon_deg, ll.lat_deg);
      EXPECT_NEAR(back[0], x, 1e-6) << loc.name;
      EXPECT_NEAR(back[1], y, 1e-6) << loc.name;
    }
  }
  // Latitude grows north, longitude east: 1 km north of the origin is ~0.009°.
  const LonLat north = AzimuthalProjection("singapore-onenorth").to_lonlat(0, 1000);
  EXPECT_NEAR(north.lat_deg - 1.2882100868743724, 1000.0 / kDevkitEarthRadiusM * 180.0 / M_PI, 1e-12);
}

TEST(Georef, ProjString) {
  EXPECT_EQ(aeqd_proj_string("boston-seaport"),
            "+proj=aeqd +lat_0=42.336849169438615 +lon_0=-71.05785369873047 +R=6378137 +x_0=0 "
            "+y_0=0 +units=m");
  EXPECT_EQ(aeqd_proj_string("singapore-queenstown"),
            "+proj=aeqd +lat_0=1.2782562240223188 +lon_0=103.76741409301758 +R=6378137 +x_0=0 "
            "+y_0=0 +units=m");
}

}  // namespace
}  // namespace nsg::geometry

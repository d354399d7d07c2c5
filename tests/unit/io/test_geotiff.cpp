// GeoTIFF encode/decode: round trips, determinism, rejection of what we do not write, and
// GDAL's reading of the CRS and corners (docs/dataset-format.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "io_fixtures.h"
#include "nsg/core/error.h"
#include "nsg/core/parallel.h"
#include "nsg/core/sha256.h"
#include "nsg/geometry/georef.h"
#include "nsg/io/raster.h"
#include "test_support.h"

namespace nsg::io {
namespace {

using test::pattern_f32;
using test::pattern_u8;

const GeoRef kBoston{"boston-seaport", 1200.4, 1800.6, 0.2};

void expect_round_trip(const Raster& r, const GeoTiffOptions& options = {}) {
  const auto bytes = encode_geotiff(r, kBoston, options);
  ASSERT_GT(bytes.size(), 8u);
  EXPECT_EQ(bytes[0], 'I');  // little-endian TIFF
  GeoRef back;
  const Raster d = decode_geotiff(bytes, "tile.tif", &back);
  EXPECT_EQ(d.width, r.width);
  EXPECT_EQ(d.height, r.height);
  EXPECT_EQ(d.bands, r.bands);
  EXPECT_EQ(d.type, r.type);
  EXPECT_TRUE(d.data == r.data);
  EXPECT_EQ(back.location, "boston-seaport");
  EXPECT_EQ(back.x_west_m, kBoston.x_west_m);
  EXPECT_EQ(back.y_north_m, kBoston.y_north_m);
  EXPECT_EQ(back.resolution_m, kBoston.resolution_m);
}

TEST(GeoTiff, RoundTripUInt8OneBand) { expect_round_trip(pattern_u8(256, 256, 1)); }
TEST(GeoTiff, RoundTripUInt8Rgb) { expect_round_trip(pattern_u8(256, 256, 3)); }
TEST(GeoTiff, RoundTripFloat32) {
  GeoTiffOptions o;
  o.nodata = -1.0;
  expect_round_trip(pattern_f32(256, 256), o);
}
// 600 rows = strips of 256, 256, 88; odd width checks row strides.
TEST(GeoTiff, RoundTripSeveralStripsAndOddWidth) {
  expect_round_trip(pattern_u8(131, 600, 3));
  expect_round_trip(pattern_f32(77, 513));
}
TEST(GeoTiff, RoundTripEveryDeflateLevel) {
  for (int level = 1; level <= 9; ++level) {
    GeoTiffOptions o;
    o.deflate_level = level;
    expect_round_trip(pattern_u8(64, 64, 1), o);
  }
}

TEST(GeoTiff, IdenticalInputGivesIdenticalBytes) {
  GeoTiffOptions o;
  o.nodata = 0;
  for (const Raster& r : {pattern_u8(256, 256, 1), pattern_u8(256, 256, 3), pattern_f32(256, 256)}) {
    const auto a = encode_geotiff(r, kBoston, o);
    const auto b = encode_geotiff(r, kBoston, o);
    EXPECT_TRUE(a == b);
  }
  // … and the georef is really in the bytes.
  GeoRef moved = kBoston;
  moved.x_west_m += 0.2;
  EXPECT_FALSE(encode_geotiff(pattern_u8(8, 8, 1), kBoston) == encode_geotiff(pattern_u8(8, 8, 1), moved));
}

// The pipeline encodes tiles on several threads: same bytes as one thread.
TEST(GeoTiff, ConcurrentEncodingGivesTheSameBytes) {
  const std::vector<Raster> rasters = {pattern_u8(256, 256, 1), pattern_u8(256, 256, 3), pattern_f32(256, 256)};
  std::vector<std::vector<uint8_t>> serial, parallel(24);
  for (const Raster& r : rasters) serial.push_back(encode_geotiff(r, kBoston));
  nsg::parallel_for(parallel.size(), 4,
                    [&](size_t i) { parallel[i] = encode_geotiff(rasters[i % rasters.size()], kBoston); });
  for (size_t i = 0; i < parallel.size(); ++i) EXPECT_TRUE(parallel[i] == serial[i % rasters.size()]);
}

TEST(GeoTiff, OtherLocationIsRecognisedOnDecode) {
  GeoRef g{"singapore-queenstown", 10.0, 20.0, 0.5};
  GeoRef back;
  decode_geotiff(encode_geotiff(pattern_u8(4, 4, 1), g), "q.tif", &back);
  EXPECT_EQ(back.location, "singapore-queenstown");
  EXPECT_EQ(back.resolution_m, 0.5);
}

TEST(GeoTiff, RejectsUnsupportedRastersAndOptions) {
  Raster f3 = pattern_f32(4, 4);
  f3.bands = 3;
  f3.data.resize(f3.expected_bytes());
  EXPECT_THROW(encode_geotiff(f3, kBoston), DataError);
  EXPECT_THROW(encode_geotiff(pattern_u8(4, 4, 2), kBoston), DataError);
  Raster short_data = pattern_u8(4, 4, 1);
  short_data.data.pop_back();
  EXPECT_THROW(encode_geotiff(short_data, kBoston), DataError);
  EXPECT_THROW(encode_geotiff(pattern_u8(4, 4, 1), GeoRef{"mars", 0, 0, 0.2}), ConfigError);
  EXPECT_THROW(encode_geotiff(pattern_u8(4, 4, 1), GeoRef{"boston-seaport", 0, 0, 0.0}), ConfigError);
  GeoTiffOptions bad_level;
  bad_level.deflate_level = 0;
  EXPECT_THROW(encode_geotiff(pattern_u8(4, 4, 1), kBoston, bad_level), ConfigError);
  GeoTiffOptions bad_nodata;
  bad_nodata.nodata = -1.0;  // not representable in uint8
  EXPECT_THROW(encode_geotiff(pattern_u8(4, 4, 1), kBoston, bad_nodata), ConfigError);
}

void expect_parse_error_naming(std::span<const uint8_t> bytes, const std::string& name) {
  try {
    decode_geotiff(bytes, name);
    FAIL() << "expected ParseError";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), name);
    EXPECT_NE(std::string(e.what()).find(name), std::string::npos);
  }
}

TEST(GeoTiff, CorruptInputIsAParseErrorNamingTheFile) {
  const std::vector<uint8_t> junk = {'n', 'o', 't', ' ', 'a', ' ', 't', 'i', 'f', 'f'};
  expect_parse_error_naming(junk, "junk.tif");
  expect_parse_error_naming({}, "empty.tif");
  const auto good = encode_geotiff(pattern_u8(256, 256, 3), kBoston);
  // libtiff writes the directory last, so a cut anywhere before it loses the directory.
  for (size_t cut : {size_t{4}, size_t{16}, good.size() / 2}) {
    expect_parse_error_naming(std::span(good).first(cut), "cut.tif");
  }
  // Damage the compressed strip: zlib fails and we say so.
  auto damaged = good;
  for (size_t i = 8; i < 200 && i < damaged.size(); ++i) damaged[i] ^= 0x5a;
  expect_parse_error_naming(damaged, "damaged.tif");
}

// TIFFs from another writer (Pillow): a plain uncompressed 8-bit image decodes, but has no
// georef to give; a 16-bit image is refused.
TEST(GeoTiff, ForeignTiffsDecodeOrAreRefusedClearly) {
  nsg::test::TempDir dir("io-pil");
  const auto r =
      nsg::test::run_program({"/usr/bin/python3", "-c",
                              "import sys\nfrom PIL import Image\n"
                              "im = Image.new('L', (5, 3))\nim.putdata(list(range(15)))\nim.save(sys.argv[1])\n"
                              "Image.new('I;16', (4, 4)).save(sys.argv[2])\n",
                              (dir / "plain.tif").string(), (dir / "deep.tif").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string plain = nsg::test::read_text(dir / "plain.tif");
  const std::span<const uint8_t> plain_bytes(reinterpret_cast<const uint8_t*>(plain.data()), plain.size());
  const Raster d = decode_geotiff(plain_bytes, "plain.tif");
  ASSERT_EQ(d.width, 5);
  ASSERT_EQ(d.height, 3);
  for (size_t i = 0; i < 15; ++i) EXPECT_EQ(d.data[i], i);
  GeoRef g;
  EXPECT_THROW(decode_geotiff(plain_bytes, "plain.tif", &g), ParseError);
  const std::string deep = nsg::test::read_text(dir / "deep.tif");
  try {
    decode_geotiff(std::span(reinterpret_cast<const uint8_t*>(deep.data()), deep.size()), "deep.tif");
    FAIL() << "expected ParseError";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), "deep.tif");
    EXPECT_NE(std::string(e.what()).find("16 bits"), std::string::npos) << e.what();
  }
}

// Pillow + numpy (what the dataset's Python check uses) read our three layouts back.
TEST(GeoTiff, PillowReadsEveryLayout) {
  nsg::test::TempDir dir("io-pil-read");
  const std::vector<std::pair<std::string, Raster>> layers = {
      {"lidar", pattern_u8(256, 256, 1)}, {"rgb", pattern_u8(256, 256, 3)}, {"vehicle", pattern_f32(256, 256)}};
  std::vector<std::string> args = {
      "/usr/bin/python3", "-c",
      "import sys\nimport numpy as np\nfrom PIL import Image\n"
      "for path in sys.argv[1:]:\n"
      "    a = np.array(Image.open(path + '.tif'))\n"
      "    print(a.shape, a.dtype)\n"
      "    open(path + '.raw', 'wb').write(a.astype(a.dtype.newbyteorder('<')).tobytes())\n"};
  for (const auto& [name, raster] : layers) {
    const auto bytes = encode_geotiff(raster, kBoston);
    nsg::test::write_text(dir / (name + ".tif"), std::string(bytes.begin(), bytes.end()));
    args.push_back((dir / name).string());
  }
  const auto r = nsg::test::run_program(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "(256, 256) uint8\n(256, 256, 3) uint8\n(256, 256) float32\n");
  for (const auto& [name, raster] : layers) {
    const std::string raw = nsg::test::read_text(dir / (name + ".raw"));
    EXPECT_TRUE(std::equal(raw.begin(), raw.end(), raster.data.begin(), raster.data.end(), [](char a, uint8_t b) {
      return static_cast<uint8_t>(a) == b;
    })) << name;
  }
}

// ---- GDAL's view of a written tile -------------------------------------------------------------

bool have_program(const std::string& name) {
  return nsg::test::run_program({"/bin/sh", "-c", "command -v " + name}).exit_code == 0;
}

std::filesystem::path write_tile(const nsg::test::TempDir& dir, const GeoRef& g) {
  GeoTiffOptions o;
  o.nodata = 0;
  const auto bytes = encode_geotiff(pattern_u8(256, 256, 1), g, o);
  const auto path = dir / "tile.lidar.tif";
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  return path;
}

double proj_param(const std::string& proj4, const std::string& key) {
  const auto at = proj4.find("+" + key + "=");
  if (at == std::string::npos) return NAN;
  return std::stod(proj4.substr(at + key.size() + 2));
}

TEST(GeoTiff, GdalinfoReportsAeqdCrsAndCorners) {
  if (!have_program("gdalinfo")) GTEST_SKIP() << "optional tool gdalinfo not installed";
  nsg::test::TempDir dir("io-gdal");
  const auto path = write_tile(dir, kBoston);
  const auto text = nsg::test::run_program({"gdalinfo", "-proj4", path.string()});
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_EQ(text.err, "");  // no warnings about our tags
  const auto& boston = geometry::location_info("boston-seaport");
  const auto q = text.out.find("'+proj=aeqd");
  ASSERT_NE(q, std::string::npos) << text.out;
  const std::string proj4 = text.out.substr(q + 1, text.out.find('\'', q + 1) - q - 1);
  EXPECT_NEAR(proj_param(proj4, "lat_0"), boston.origin_lat_deg, 1e-12) << proj4;
  EXPECT_NEAR(proj_param(proj4, "lon_0"), boston.origin_lon_deg, 1e-12) << proj4;
  EXPECT_EQ(proj_param(proj4, "R"), 6378137.0) << proj4;
  EXPECT_EQ(proj_param(proj4, "x_0"), 0.0) << proj4;
  EXPECT_NE(text.out.find("NoData Value=0"), std::string::npos);

  const auto js = nsg::test::run_program({"gdalinfo", "-json", path.string()});
  ASSERT_EQ(js.exit_code, 0) << js.err;
  const auto info = nlohmann::json::parse(js.out);
  const auto& corners = info.at("cornerCoordinates");
  EXPECT_NEAR(corners.at("upperLeft")[0].get<double>(), kBoston.x_west_m, 1e-9);
  EXPECT_NEAR(corners.at("upperLeft")[1].get<double>(), kBoston.y_north_m, 1e-9);
  EXPECT_NEAR(corners.at("lowerRight")[0].get<double>(), kBoston.x_west_m + 256 * 0.2, 1e-9);
  EXPECT_NEAR(corners.at("lowerRight")[1].get<double>(), kBoston.y_north_m - 256 * 0.2, 1e-9);
  EXPECT_EQ(info.at("size")[0].get<int>(), 256);
  EXPECT_EQ(info.at("bands")[0].at("type").get<std::string>(), "Byte");
}

// GDAL's lon/lat of the pixel corners (on the file's own sphere) equal the devkit formula.
TEST(GeoTiff, GdalLonLatCornersMatchDevkitFormula) {
  if (!have_program("gdaltransform")) GTEST_SKIP() << "optional tool gdaltransform not installed";
  nsg::test::TempDir dir("io-gdal-ll");
  for (const GeoRef& g : {kBoston, GeoRef{"singapore-onenorth", 800.0, 1500.2, 0.2}}) {
    const auto path = write_tile(dir, g);
    const auto r =
        nsg::test::run_program({"/bin/sh", "-c",
                                "printf '0 0\\n256 256\\n0 256\\n256 0\\n' | gdaltransform -output_xy -t_srs "
                                "'+proj=longlat +R=6378137 +no_defs' '" +
                                    path.string() + "'"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    std::istringstream in(r.out);
    const std::vector<std::pair<double, double>> pixel = {{0, 0}, {256, 256}, {0, 256}, {256, 0}};
    for (const auto& [col, row] : pixel) {
      double lon = NAN, lat = NAN;
      ASSERT_TRUE(in >> lon >> lat) << r.out;
      const auto want =
          geometry::map_to_lonlat(g.location, g.x_west_m + col * g.resolution_m, g.y_north_m - row * g.resolution_m);
      EXPECT_NEAR(lon, want.lon_deg, 1e-8) << g.location << " pixel " << col << "," << row;
      EXPECT_NEAR(lat, want.lat_deg, 1e-8) << g.location << " pixel " << col << "," << row;
    }
  }
}

}  // namespace
}  // namespace nsg::io

#pragma once
// In-memory rasters and their GeoTIFF encoding (docs/dataset-format.md). libtiff and libgeotiff
// stay behind this interface.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace nsg::io {

enum class SampleType { kUInt8, kFloat32 };

// Row-major, bands interleaved (pixel-major), row 0 = north edge, column 0 = west edge.
struct Raster {
  int width = 0;
  int height = 0;
  int bands = 1;
  SampleType type = SampleType::kUInt8;
  std::vector<uint8_t> data;  // width*height*bands*bytes_per_sample(), native little-endian

  size_t bytes_per_sample() const;
  size_t expected_bytes() const;  // width*height*bands*bytes_per_sample()
  // Throws DataError if sizes are not positive or data has the wrong length.
  void validate() const;
};

// Where a raster lies: the map frame of `location` (origin from geometry::location_info),
// its north-west corner in map metres and the square pixel size.
struct GeoRef {
  std::string location;
  double x_west_m = 0.0;
  double y_north_m = 0.0;
  double resolution_m = 0.2;
  // Throws ConfigError for an unknown location or a non-finite / non-positive value.
  void validate() const;
};

struct GeoTiffOptions {
  int deflate_level = 1;         // 1 (fast) … 9 (small)
  std::optional<double> nodata;  // written as the GDAL_NODATA tag when set
  // For a GIS (inspect layers), in GDAL's GDAL_METADATA tag as GDAL writes it: each band's
  // description (QGIS shows it as the band's name; at most one per band) and items of the
  // first band (e.g. CLASS_0 = road). Empty: no tag (the dataset's tiles carry none).
  std::vector<std::string> band_descriptions;
  std::vector<std::pair<std::string, std::string>> band_metadata;
  // A 1-band uint8 raster's palette (value → RGB; at most 256 entries, the rest black):
  // PhotometricInterpretation palette and a ColorMap, which QGIS and GDAL show as colours.
  std::vector<std::array<uint8_t, 3>> color_table;
  void validate() const;  // throws ConfigError
};

// Encodes uint8 1- or 3-band or float32 1-band rasters as a deflate GeoTIFF in memory,
// with the location's azimuthal-equidistant CRS (docs/dataset-format.md). Identical input gives
// identical bytes (no time stamps or software tags).
std::vector<uint8_t> encode_geotiff(const Raster& raster, const GeoRef& georef, const GeoTiffOptions& options = {});

// Decodes what encode_geotiff writes (uint8 1/3-band, float32 1-band, strips, contiguous
// samples, any compression libtiff knows). Throws ParseError naming `name` otherwise. If
// `georef` is given the file must carry ModelTiepoint and ModelPixelScale with square
// pixels; georef->location is the known location whose origin matches the file's
// ProjCenterLat/Long keys, or "" if none does.
// Images larger than 4096 x 4096 pixels are refused from the header, before allocating.
Raster decode_geotiff(std::span<const uint8_t> bytes, const std::string& name, GeoRef* georef = nullptr);

// What a GeoTIFF's header says, read without decoding a pixel (ParseError as above), so a
// reader can check it against the expected tile format before allocating anything.
struct RasterHeader {
  int width = 0;
  int height = 0;
  int bands = 1;
  SampleType type = SampleType::kUInt8;
};
RasterHeader read_geotiff_header(std::span<const uint8_t> bytes, const std::string& name);
// DataError naming `name` and `record` when `got` differs from `want` in size, bands or type.
void check_raster_header(const RasterHeader& got, const RasterHeader& want, const std::string& name,
                         const std::string& record);

}  // namespace nsg::io

#include <cmath>
#include <string>

#include "nsg/core/error.h"
#include "nsg/geometry/georef.h"
#include "nsg/io/raster.h"

namespace nsg::io {

size_t Raster::bytes_per_sample() const { return type == SampleType::kFloat32 ? 4 : 1; }

size_t Raster::expected_bytes() const {
  if (width <= 0 || height <= 0 || bands <= 0) return 0;
  return static_cast<size_t>(width) * static_cast<size_t>(height) * static_cast<size_t>(bands) * bytes_per_sample();
}

void Raster::validate() const {
  const std::string size = std::to_string(width) + "x" + std::to_string(height) + "x" + std::to_string(bands);
  NSG_CHECK(width > 0 && height > 0 && bands > 0, DataError, "", "raster " + size,
            "width, height and bands must be positive");
  NSG_CHECK(data.size() == expected_bytes(), DataError, "", "raster " + size,
            "data must hold " + std::to_string(expected_bytes()) + " bytes, has " + std::to_string(data.size()));
}

void GeoRef::validate() const {
  geometry::location_info(location);  // throws ConfigError naming the valid locations
  NSG_CHECK(std::isfinite(x_west_m) && std::isfinite(y_north_m), ConfigError, "", "georef " + location,
            "x_west_m and y_north_m must be finite");
  NSG_CHECK(std::isfinite(resolution_m) && resolution_m > 0.0, ConfigError, "", "resolution_m",
            "a positive finite pixel size");
}

void GeoTiffOptions::validate() const {
  NSG_CHECK(deflate_level >= 1 && deflate_level <= 9, ConfigError, "", "deflate_level",
            "an integer in 1..9, got " + std::to_string(deflate_level));
  NSG_CHECK(color_table.size() <= 256, ConfigError, "", "color_table",
            "at most 256 entries (uint8 values), got " + std::to_string(color_table.size()));
  for (const auto& [name, value] : band_metadata)
    NSG_CHECK(!name.empty() && name.find_first_of(" <>&\"'") == std::string::npos, ConfigError, "", "band_metadata",
              "item names without spaces or XML characters, got '" + name + "'");
}

}  // namespace nsg::io

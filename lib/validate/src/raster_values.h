#pragma once
// validate's checks of a tile's raster values (dataset.cpp decodes the rasters): the vehicle
// layer's no-data rule, the coverage flags against the layers' data, and meta.json's
// coverage fractions and vehicle pixel count against the rasters.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>

#include "nsg/io/raster.h"
#include "nsg/io/tile_meta.h"

namespace nsg::validate {

// One finding: (check, subject, message); the checker keeps it if the check is selected.
using ReportFinding = std::function<void(const std::string&, const std::string&, const std::string&)>;

// vehicle.tif (float32, `pixels` values): each −1 (no data) or in [0, 1) ("raster.nodata"
// names `subject`, the count and the first bad value). Returns the pixels in [0, 1).
int64_t check_vehicle_values(const io::Raster& vehicle, size_t pixels, const std::string& subject,
                             const ReportFinding& report);

// coverage.tif among the decoded `rasters` (by member suffix; nothing to check without it):
// flags only of the declared bits, a layer's bit wherever that layer has data
// ("raster.nodata"), and meta.json's /coverage fractions and /counts/vehicle_px (when
// `vehicle_px` ≥ 0) equal to what the rasters hold ("meta.counts"). `base` is "shard/key".
void check_coverage_values(const std::map<std::string, io::Raster>& rasters, size_t pixels, const std::string& base,
                           const std::optional<io::TileMeta>& meta, int64_t vehicle_px, const ReportFinding& report);

}  // namespace nsg::validate

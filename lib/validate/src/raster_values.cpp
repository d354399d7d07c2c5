#include "raster_values.h"

#include <cmath>
#include <cstring>

#include "nsg/core/coverage_bits.h"
#include "nsg/core/strings.h"

namespace nsg::validate {

int64_t check_vehicle_values(const io::Raster& vehicle, size_t pixels, const std::string& subject,
                             const ReportFinding& report) {
  int64_t vehicle_px = 0;
  int64_t bad = 0;
  float first_bad = 0;
  for (size_t i = 0; i < pixels; ++i) {
    float v;
    std::memcpy(&v, vehicle.data.data() + 4 * i, 4);
    if (v == -1.0f) continue;
    if (v >= 0.0f && v < 1.0f) {
      ++vehicle_px;
    } else if (bad++ == 0) {
      first_bad = v;
    }
  }
  if (bad > 0)
    report("raster.nodata", subject,
           strprintf("values in {-1} or [0, 1); %lld pixels are not (first: %s)", static_cast<long long>(bad),
                     format_double(first_bad).c_str()));
  return vehicle_px;
}

void check_coverage_values(const std::map<std::string, io::Raster>& rasters, size_t pixels, const std::string& base,
                           const std::optional<io::TileMeta>& meta, int64_t vehicle_px, const ReportFinding& report) {
  auto cov = rasters.find("coverage.tif");
  if (cov == rasters.end()) return;
  const uint8_t* flags = cov->second.data.data();
  int64_t bad_flags = 0, lidar_px = 0, rgb_px = 0, sem_px = 0;
  int64_t unflagged[3] = {0, 0, 0};
  const auto* lidar = rasters.count("lidar.tif") ? rasters.at("lidar.tif").data.data() : nullptr;
  const auto* rgb = rasters.count("rgb.tif") ? rasters.at("rgb.tif").data.data() : nullptr;
  const auto* sem = rasters.count("semantic.tif") ? rasters.at("semantic.tif").data.data() : nullptr;
  for (size_t i = 0; i < pixels; ++i) {
    const uint8_t f = flags[i];
    if ((f & ~kCoverageAll) != 0) ++bad_flags;
    lidar_px += (f & kCoverageLidar) != 0;
    rgb_px += (f & kCoverageRgb) != 0;
    sem_px += (f & kCoverageSemantic) != 0;
    if (lidar && lidar[i] != 0 && !(f & kCoverageLidar)) ++unflagged[0];
    if (rgb && (rgb[3 * i] | rgb[3 * i + 1] | rgb[3 * i + 2]) != 0 && !(f & kCoverageRgb)) ++unflagged[1];
    if (sem && sem[i] != 255 && !(f & kCoverageSemantic)) ++unflagged[2];
  }
  if (bad_flags > 0)
    report("raster.nodata", base + ".coverage.tif",
           strprintf("flags in 0..%d; %lld pixels are not", kCoverageAll, static_cast<long long>(bad_flags)));
  const char* layers[3] = {"lidar", "rgb", "semantic"};
  const int bits[3] = {kCoverageLidar, kCoverageRgb, kCoverageSemantic};
  for (int k = 0; k < 3; ++k)
    if (unflagged[k] > 0)
      report("raster.nodata", base + "." + layers[k] + ".tif",
             strprintf("coverage bit %d wherever %s has data; %lld pixels with data lack it", bits[k], layers[k],
                       static_cast<long long>(unflagged[k])));
  if (!meta) return;
  const std::string subject = base + ".meta.json";
  const int64_t counts[3] = {lidar_px, rgb_px, sem_px};
  const double fractions[3] = {meta->coverage_lidar, meta->coverage_rgb, meta->coverage_semantic};
  for (int k = 0; k < 3; ++k) {
    const double want = static_cast<double>(counts[k]) / static_cast<double>(pixels);
    if (std::abs(fractions[k] - want) > 1e-9)
      report("meta.counts", subject + ":/coverage/" + layers[k],
             "the coverage raster's fraction " + format_double(want) + ", got " + format_double(fractions[k]));
  }
  if (vehicle_px >= 0 && meta->vehicle_px != vehicle_px)
    report("meta.counts", subject + ":/counts/vehicle_px",
           strprintf("%lld (vehicle.tif), got %lld", static_cast<long long>(vehicle_px),
                     static_cast<long long>(meta->vehicle_px)));
}

}  // namespace nsg::validate

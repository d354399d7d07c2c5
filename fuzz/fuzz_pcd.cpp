// The LiDAR .pcd.bin reader.
#include <cmath>
#include <cstdlib>

#include "fuzz_support.h"
#include "nsg/nuscenes/lidar.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::filesystem::path file = nsg::fuzz::input_file(data, size);
  nsg::fuzz::expect_only_input_errors([&] {
    const std::vector<nsg::nuscenes::LidarPoint> points = nsg::nuscenes::read_lidar_points(file);
    // Accepted input: exactly size / 20 points, all finite (the documented contract).
    if (points.size() * 20 != size) std::abort();
    for (const auto& p : points)
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) || !std::isfinite(p.intensity))
        std::abort();
  });
  return 0;
}

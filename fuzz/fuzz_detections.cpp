// The nuScenes detection results reader.
#include <cmath>
#include <cstdlib>

#include "fuzz_support.h"
#include "nsg/nuscenes/detections.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::filesystem::path file = nsg::fuzz::input_file(data, size);
  nsg::fuzz::expect_only_input_errors([&] {
    const nsg::nuscenes::DetectionResults r = nsg::nuscenes::read_detections(file);
    // Accepted input keeps the documented guarantees.
    for (const auto& s : r.samples) {
      if (s.boxes.size() > nsg::nuscenes::kMaxBoxesPerSample) std::abort();
      for (const auto& b : s.boxes)
        if (!(b.detection_score >= 0.0 && b.detection_score <= 1.0)) std::abort();
    }
  });
  return 0;
}

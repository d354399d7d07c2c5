// The map expansion reader, plus the centerline discretization every loaded map must
// survive (arcline paths that passed the reader's checks).
#include "fuzz_support.h"
#include "nsg/nuscenes/map_expansion.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::filesystem::path file = nsg::fuzz::input_file(data, size);
  nsg::fuzz::expect_only_input_errors([&] {
    const nsg::nuscenes::MapExpansion map = nsg::nuscenes::load_map_expansion_file(file);
    (void)map.discretize_centerlines(2.0);
  });
  return 0;
}

// `nsgraph graphify`'s map readers and the skeleton chain: a stranger's PNG (8/16-bit), one-band
// GeoTIFF or .npy probability map, read by its first bytes (skeleton::read_map_file: sizes
// checked from the header before decoding), then graphified when small enough for a fuzz
// run's time. Every graph edge must join two of its nodes, and every node lie on the map.
#include <cstdlib>

#include "fuzz_support.h"
#include "nsg/skeleton/graphify.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  nsg::fuzz::expect_only_input_errors([&] {
    const cv::Mat map = nsg::skeleton::read_map_file(nsg::fuzz::input_file(data, size));
    if (map.rows < 1 || map.cols < 1 || map.rows > nsg::skeleton::kMaxMapSidePx ||
        map.cols > nsg::skeleton::kMaxMapSidePx || map.channels() != 1)
      std::abort();
    if (static_cast<int64_t>(map.rows) * map.cols > 256 * 256) return;  // the reader is the target beyond this
    const nsg::metrics::Graph g = nsg::skeleton::graphify(map, nsg::skeleton::GraphifyOptions{});
    for (const auto& e : g.edges)
      if (e[0] < 0 || e[1] < 0 || static_cast<size_t>(e[0]) >= g.nodes.size() ||
          static_cast<size_t>(e[1]) >= g.nodes.size())
        std::abort();
    for (const auto& n : g.nodes)
      if (!(n.u >= -1 && n.v >= -1 && n.u <= map.cols && n.v <= map.rows)) std::abort();
  });
  return 0;
}

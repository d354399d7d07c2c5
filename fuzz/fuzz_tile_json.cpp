// Dataset JSON members as nsgraph.Dataset, stats and the report read them: the strict
// parser (nesting capped, repeated keys refused), the graph conversion (and a map-update
// tile's prior graph) and the checked
// meta.json reader. Whatever it accepts nests at most
// kMaxJsonDepth deep, so the Python conversion that follows cannot recurse further.
#include <cstdlib>
#include <string_view>
#include <vector>

#include "fuzz_support.h"
#include "nsg/core/json.h"
#include "nsg/io/tile_graph.h"
#include "nsg/io/tile_meta.h"

namespace {
int depth_of(const nlohmann::json& root) {
  int deepest = 0;
  std::vector<std::pair<const nlohmann::json*, int>> stack{{&root, 0}};
  while (!stack.empty()) {
    const auto [j, d] = stack.back();
    stack.pop_back();
    if (!j->is_structured()) continue;
    deepest = std::max(deepest, d + 1);
    for (const nlohmann::json& child : *j) stack.push_back({&child, d + 1});
  }
  return deepest;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  nsg::fuzz::expect_only_input_errors([&] {
    const nlohmann::json doc =
        nsg::parse_json_strict(std::string_view(reinterpret_cast<const char*>(data), size), "k.meta.json");
    if (depth_of(doc) > nsg::kMaxJsonDepth) std::abort();
    nsg::fuzz::expect_only_input_errors([&] { (void)nsg::io::tile_graph_from_json(doc, "k.graph.json"); });
    nsg::fuzz::expect_only_input_errors([&] { (void)nsg::io::tile_prior_graph_from_json(doc, "k.graph.json"); });
    (void)nsg::io::tile_meta_from_json(doc, "k.meta.json");
  });
  return 0;
}

// graphify: per tile, a map → the skeleton chain's anchor graph → an undirected lane graph
// (each pair as two opposite edges), keyed by the map file's stem.
#include "nsg/skeleton/graphify.h"

#include <map>
#include <set>

#include "nsg/core/error.h"

namespace nsg::skeleton {

const options::Table<GraphifyOptions>& graphify_option_table() {
  static const options::Table<GraphifyOptions> table = [] {
    options::Table<GraphifyOptions> t;
    options::schema_version_option(t);  // as every config file of v1
    t.include(&GraphifyOptions::skeleton, skeleton_option_table());
    return t;
  }();
  return table;
}

void GraphifyOptions::validate() const { graphify_option_table().check(*this); }

options::OrderedJson graphify_config_schema() {
  return options::config_schema(
      graphify_option_table().specs(), "https://nuscenesgraph.org/schemas/v1/graphify-config.schema.json",
      "NuScenesGraph graphify config (v1)",
      "Options of `nsgraph graphify` (maps to lane graphs). A file may give any subset of the keys; the others keep "
      "their defaults. Generated from the options' declarations: `nsgraph graphify --list-options --format schema`.");
}

GraphifyOptions resolve_graphify_config(const std::filesystem::path& file, const std::vector<std::string>& settings,
                                        const std::vector<options::FlagValue>& flags) {
  options::Origins origins;
  return options::resolve_config(graphify_option_table(), file, settings, flags, "threshold=0.4", origins);
}

cv::Mat likelihood_of(const cv::Mat& map, const std::string& name) {
  const int type = map.type();
  NSG_CHECK(type == CV_8UC1 || type == CV_16UC1 || type == CV_32FC1, DataError, name, "map",
            "one channel of uint8, uint16 or float32");
  NSG_CHECK(map.rows >= 1 && map.cols >= 1 && map.rows <= kMaxMapSidePx && map.cols <= kMaxMapSidePx, DataError, name,
            "map", "width and height each 1 … " + std::to_string(kMaxMapSidePx) + " px");
  cv::Mat out;
  if (type == CV_32FC1) {
    NSG_CHECK(cv::checkRange(map), DataError, name, "map", "finite values (no NaN or infinity)");
    map.copyTo(out);
    return out;
  }
  double max_value = 0.0;
  cv::minMaxLoc(map, nullptr, &max_value);
  // A mask of 0 and 1 (as numpy's astype(uint8) of a boolean mask gives) is a mask, not a
  // map of likelihoods near 0.
  const double full_scale = max_value <= 1.0 ? 1.0 : type == CV_8UC1 ? 255.0 : 65535.0;
  map.convertTo(out, CV_32F, 1.0 / full_scale);
  return out;
}

metrics::Graph graphify(const cv::Mat& map, const GraphifyOptions& options, const std::string& name) {
  options.validate();
  const AnchorGraph anchors = skeleton_anchors(likelihood_of(map, name), options.skeleton);
  // Each undirected pair once (two branches between the same vertices collapse), then as
  // two edges; nodes without a pair are left out.
  std::set<std::array<int, 2>> pairs;
  for (const auto& p : anchors.pairs) pairs.insert({std::min(p[0], p[1]), std::max(p[0], p[1])});
  std::vector<int64_t> index(anchors.nodes.size(), -1);
  metrics::Graph g;
  auto node = [&](int a) {
    auto& i = index[static_cast<size_t>(a)];
    if (i < 0) {
      i = static_cast<int64_t>(g.nodes.size());
      g.nodes.push_back({anchors.nodes[static_cast<size_t>(a)][0], anchors.nodes[static_cast<size_t>(a)][1]});
    }
    return i;
  };
  for (const auto& p : anchors.pairs) {
    if (p[0] == p[1] || !pairs.erase({std::min(p[0], p[1]), std::max(p[0], p[1])})) continue;
    const int64_t a = node(p[0]), b = node(p[1]);
    g.edges.push_back({a, b});
    g.edges.push_back({b, a});
  }
  return g;
}

namespace {

// The map files of a folder by tile key, in key order.
std::map<std::string, std::filesystem::path> map_files_of(const std::filesystem::path& folder) {
  std::map<std::string, std::filesystem::path> files;
  std::error_code ec;
  for (std::filesystem::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    const std::filesystem::path& p = it->path();
    if (!is_map_file_name(p) || !it->is_regular_file()) continue;
    const std::string key = p.stem().string();
    const auto [at, fresh] = files.emplace(key, p);
    NSG_CHECK(fresh, DataError, folder.string(), key,
              "one map per tile key, got " + at->second.filename().string() + " and " + p.filename().string());
  }
  NSG_CHECK(!ec, IoError, folder.string(), "", "a readable folder: " + ec.message());
  NSG_CHECK(!files.empty(), DataError, folder.string(), "",
            "map files named <tile key>.png, .tif, .tiff or .npy (found none)");
  return files;
}

}  // namespace

metrics::GraphSet graphify_input(const std::filesystem::path& input, const GraphifyOptions& options) {
  options.validate();
  metrics::GraphSet out;
  if (std::filesystem::is_directory(input)) {
    for (const auto& [key, file] : map_files_of(input))
      out[key] = graphify(read_map_file(file), options, file.string());
    return out;
  }
  out[input.stem().string()] = graphify(read_map_file(input), options, input.string());
  return out;
}

}  // namespace nsg::skeleton

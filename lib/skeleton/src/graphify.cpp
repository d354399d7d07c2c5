// graphify: per tile, a map → the skeleton chain's anchor graph → a lane graph, keyed by
// the map file's stem: undirected (each pair as two opposite edges), or directed by a
// heading map (the paper's orientation rule with headings in place of LaneDirNet's votes).
#include "nsg/skeleton/graphify.h"

#include <cmath>
#include <map>
#include <set>

#include "nsg/core/error.h"

namespace nsg::skeleton {

SkeletonOptions graphify_skeleton_defaults() {
  SkeletonOptions s;
  s.split_crossings = true;
  return s;
}

const options::Table<GraphifyOptions>& graphify_option_table() {
  static const options::Table<GraphifyOptions> table = [] {
    options::Table<GraphifyOptions> t;
    options::schema_version_option(t);  // as every config file of v1
    t.include(&GraphifyOptions::skeleton, skeleton_option_table());
    t.integer("heading_window_px", &GraphifyOptions::heading_window_px)
        .unit("px")
        .range(options::between(0, 32))
        .help("Directed mode (--heading): half the side of the window of headings averaged at an anchor");
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

void check_heading_map(const cv::Mat& heading, const cv::Size& map_size, const std::string& name) {
  NSG_CHECK(heading.type() == CV_32FC1, DataError, name, "heading map",
            "one channel of float32 (fractions of a turn clockwise from north, negative where unknown)");
  NSG_CHECK(heading.size() == map_size, DataError, name, "heading map",
            "the size of its map, " + std::to_string(map_size.width) + " x " + std::to_string(map_size.height) +
                " px (got " + std::to_string(heading.cols) + " x " + std::to_string(heading.rows) + ")");
  for (int v = 0; v < heading.rows; ++v) {
    const float* row = heading.ptr<float>(v);
    for (int u = 0; u < heading.cols; ++u) {
      NSG_CHECK(std::isfinite(row[u]) && row[u] < 1.0f, DataError, name,
                "heading map pixel (" + std::to_string(u) + ", " + std::to_string(v) + ")",
                "a finite heading in [0, 1), or negative for unknown");
    }
  }
}

std::array<double, 2> heading_sum_px(const cv::Mat& heading, double u, double v, int window_px) {
  const int cu = static_cast<int>(std::lround(u)), cv_ = static_cast<int>(std::lround(v));
  std::array<double, 2> sum{0.0, 0.0};
  for (int y = std::max(0, cv_ - window_px); y <= std::min(heading.rows - 1, cv_ + window_px); ++y) {
    for (int x = std::max(0, cu - window_px); x <= std::min(heading.cols - 1, cu + window_px); ++x) {
      const double h = heading.at<float>(y, x);
      if (h < 0.0) continue;
      // Clockwise from north: north (0) is −v, east (0.25) is +u.
      sum[0] += std::sin(2.0 * M_PI * h);
      sum[1] -= std::cos(2.0 * M_PI * h);
    }
  }
  return sum;
}

metrics::Graph graphify(const cv::Mat& map, const GraphifyOptions& options, const std::string& name,
                        const cv::Mat* heading, const std::string& heading_name) {
  options.validate();
  const cv::Mat likelihood = likelihood_of(map, name);
  if (heading) check_heading_map(*heading, likelihood.size(), heading_name.empty() ? name : heading_name);
  const AnchorGraph anchors = skeleton_anchors(likelihood, options.skeleton);
  // Each undirected pair once (two branches between the same vertices collapse); nodes
  // without a pair are left out.
  std::set<std::array<int, 2>> pairs;
  for (const auto& p : anchors.pairs) pairs.insert({std::min(p[0], p[1]), std::max(p[0], p[1])});
  std::vector<int64_t> index(anchors.nodes.size(), -1);
  metrics::Graph g;
  auto node = [&](int a) {
    auto& i = index[static_cast<size_t>(a)];
    if (i < 0) {
      const auto& p = anchors.nodes[static_cast<size_t>(a)];
      i = static_cast<int64_t>(g.nodes.size());
      g.nodes.push_back({p[0], p[1]});
      g.node_scores.push_back(sample_bilinear(likelihood, p[0], p[1]));
    }
    return i;
  };
  auto edge = [&](int64_t from, int64_t to, double score) {
    g.edges.push_back({from, to});
    g.edge_scores.push_back(score);
  };
  for (const auto& p : anchors.pairs) {
    if (p[0] == p[1] || !pairs.erase({std::min(p[0], p[1]), std::max(p[0], p[1])})) continue;
    const auto& pa = anchors.nodes[static_cast<size_t>(p[0])];
    const auto& pb = anchors.nodes[static_cast<size_t>(p[1])];
    const int64_t a = node(p[0]), b = node(p[1]);
    const double score = segment_score(likelihood, pa, pb);
    const std::array<double, 2> ha =
        heading ? heading_sum_px(*heading, pa[0], pa[1], options.heading_window_px) : std::array<double, 2>{};
    const std::array<double, 2> hb =
        heading ? heading_sum_px(*heading, pb[0], pb[1], options.heading_window_px) : std::array<double, 2>{};
    const bool known = ha != std::array<double, 2>{} || hb != std::array<double, 2>{};
    if (!known) {  // undirected, or no heading near either end: both ways
      edge(a, b, score);
      edge(b, a, score);
    } else if (orient_a_to_b(pa, pb, ha, hb)) {
      edge(a, b, score);
    } else {
      edge(b, a, score);
    }
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

// The heading file of a tile key in a headings folder: <key>.tif|.tiff|.npy or the
// dataset's <key>.vehicle.tif.
std::filesystem::path heading_file_of(const std::filesystem::path& folder, const std::string& key) {
  for (const char* suffix : {".tif", ".tiff", ".npy", ".vehicle.tif"}) {
    const std::filesystem::path p = folder / (key + suffix);
    if (std::filesystem::is_regular_file(p)) return p;
  }
  throw DataError(folder.string(), key, "a heading map " + key + ".tif, .tiff, .npy or " + key + ".vehicle.tif");
}

metrics::Graph graphify_file(const std::filesystem::path& file, const GraphifyOptions& options,
                             const std::filesystem::path& heading_file) {
  const cv::Mat map = read_map_file(file);
  if (heading_file.empty()) return graphify(map, options, file.string());
  const cv::Mat heading = read_map_file(heading_file);
  return graphify(map, options, file.string(), &heading, heading_file.string());
}

}  // namespace

metrics::GraphSet graphify_input(const std::filesystem::path& input, const GraphifyOptions& options,
                                 const std::filesystem::path& headings) {
  options.validate();
  metrics::GraphSet out;
  const bool heading_folder = !headings.empty() && std::filesystem::is_directory(headings);
  if (std::filesystem::is_directory(input)) {
    NSG_CHECK(headings.empty() || heading_folder, DataError, headings.string(), "",
              "a folder of heading maps, one per map of the folder " + input.string());
    for (const auto& [key, file] : map_files_of(input))
      out[key] = graphify_file(file, options, heading_folder ? heading_file_of(headings, key) : headings);
    return out;
  }
  const std::string key = input.stem().string();
  out[key] = graphify_file(input, options, heading_folder ? heading_file_of(headings, key) : headings);
  return out;
}

}  // namespace nsg::skeleton

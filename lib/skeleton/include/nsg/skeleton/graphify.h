#pragma once
// `nsgraph graphify` and nsgraph.graphify: a centreline probability map or a binary mask
// per tile → the lane graph in the submission format (docs/graphify.md). The rule is the
// skeleton chain's (skeleton.h): threshold, thin, trace, prune spurs, anchors ≤ 2 m apart.
// Undirected by default (every skeleton edge written in both directions); directed when a
// heading map per tile is given (the dataset's vehicle-layer convention), each edge
// oriented by the paper's rule (orient_a_to_b) from the headings at its two anchors.
// Nodes are scored by the likelihood at the anchor, edges by the mean along them.
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>

#include <opencv2/core.hpp>

#include "nsg/core/options.h"
#include "nsg/metrics/graph.h"
#include "nsg/skeleton/skeleton.h"

namespace nsg::skeleton {

// A map's width and height are at most this (a dataset tile is 256 px; 4096 leaves room
// for finer or larger tiles), checked from the file's header before anything is allocated.
constexpr int kMaxMapSidePx = 4096;
// A map file is at most this big: a 4096 x 4096 float32 .npy is 64 MiB plus its header.
constexpr uintmax_t kMaxMapFileBytes = 80ull << 20;

// The skeleton's defaults, with the crossing rule on: a mask's lanes cross without a node.
SkeletonOptions graphify_skeleton_defaults();

struct GraphifyOptions {
  SkeletonOptions skeleton = graphify_skeleton_defaults();  // keys without a prefix: threshold, …
  // Directed mode: half the side of the square window of heading pixels averaged at an
  // anchor (3 → 7 x 7 px, 1.4 m: a lane's width at 0.2 m/px).
  int heading_window_px = 3;
  void validate() const;  // ConfigError naming the key
};
// The keys of `graphify --set` and nsgraph.graphify's keyword arguments.
const options::Table<GraphifyOptions>& graphify_option_table();
// The JSON Schema of a graphify config file (schemas/v1/graphify-config.schema.json).
options::OrderedJson graphify_config_schema();
// The options from a config file ("" = none), then each --set "key=value", then flags.
GraphifyOptions resolve_graphify_config(const std::filesystem::path& file, const std::vector<std::string>& settings,
                                        const std::vector<options::FlagValue>& flags);

// The map files of a folder: these extensions (lower case), the file's stem is its tile key.
bool is_map_file_name(const std::filesystem::path& file);

// A map file as a single-channel cv::Mat (CV_8U, CV_16U or CV_32F). The kind is read from
// the file's first bytes, not its name: PNG (8- or 16-bit grayscale), TIFF (GeoTIFF, one
// band, uint8 or float32), NumPy .npy (2-D, uint8 or float32). Sizes are checked from the
// header (each side 1 … kMaxMapSidePx) before decoding. Throws IoError (missing,
// unreadable), ParseError (not one of these kinds, truncated) or DataError (another
// dtype, shape or size, non-finite values), each naming the file.
cv::Mat read_map_file(const std::filesystem::path& file);

// The likelihood in [0, 1] (CV_32F) of a map: float32 as it is; uint8 / uint16 divided by
// 255 / 65535, except a map holding only 0 and 1, which is a 0/1 mask. DataError naming
// `name` for another type or channel count.
cv::Mat likelihood_of(const cv::Mat& map, const std::string& name);

// A heading map of directed mode, as the dataset's `<key>.vehicle.tif` layer
// (docs/dataset-format.md): float32, one channel, the direction of travel as a fraction of
// a turn clockwise from map north in [0, 1) (north 0, east 0.25), negative where unknown.
// DataError naming `name` for another type, a size other than the map's, or a value that
// is not finite or is ≥ 1.
void check_heading_map(const cv::Mat& heading, const cv::Size& map_size, const std::string& name);

// The sum of the unit direction vectors (pixel frame: u right, v down) of the known
// headings in the window of half-side window_px around (u, v); zero where none is known.
std::array<double, 2> heading_sum_px(const cv::Mat& heading, double u, double v, int window_px);

// One tile: the skeleton chain on likelihood_of(map); nodes (pixel u, v) in placement
// order with the likelihood at each as its score, edges scored by segment_score. Without
// `heading` each anchor pair is written as the two edges a → b and b → a; with it (checked
// by check_heading_map, its errors naming `heading_name`, or `name` when that is empty) as
// one edge oriented by orient_a_to_b from the heading sums at its ends, or both ways where
// neither end has a known heading.
metrics::Graph graphify(const cv::Mat& map, const GraphifyOptions& options, const std::string& name = "map",
                        const cv::Mat* heading = nullptr, const std::string& heading_name = {});

// A map file, or a folder of them (is_map_file_name; other files are ignored), graphified:
// tile key (the file's stem) → graph. DataError naming the folder when it holds no map or
// two maps with one stem. With `headings` (a heading file for a single map, or a folder
// holding `<tile key>.tif|.tiff|.npy` or the dataset's `<tile key>.vehicle.tif` for
// every map) the graphs are directed; a map without its heading is a DataError naming
// the folder and the key.
metrics::GraphSet graphify_input(const std::filesystem::path& input, const GraphifyOptions& options,
                                 const std::filesystem::path& headings = {});

}  // namespace nsg::skeleton

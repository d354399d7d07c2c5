#pragma once
// The offline-BEV baseline in the frame format (`nsgraph predict --frames`, docs/frames.md):
// a tile model's predicted graphs, put back on the map and stitched per location, cut
// around each frame of an export into an OpenLane-V2 results document — so a tile model
// and a per-frame model are scored on one ground truth.
#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nsg/frames/config.h"
#include "nsg/geometry/transform.h"
#include "nsg/metrics/graph.h"

namespace nsg::frames {

// One tile's prediction: its graph in the tile's pixels (docs/dataset-format.md: u =
// (x − x_west)/res − 0.5, v = (y_north − y)/res − 0.5) and where the tile lies.
struct TilePrediction {
  std::string key;
  std::string location;
  std::array<double, 4> bounds_m{};  // x_west, y_south, x_east, y_north
  metrics::Graph graph;
};

// A frame of an export: what cutting needs.
struct FramePose {
  std::string token;
  std::string location;
  geometry::Rigid3 global_from_ego;
};

// The records of `split` of an export (through its manifest, sizes and sha256 checked),
// with the export's window and point count.
struct ExportFrames {
  std::vector<FramePose> frames;
  WindowM window;
  int centerline_points = 11;
  std::string dataset_manifest_sha256;  // the dataset the export was cut from
};
ExportFrames read_export_frames(const std::filesystem::path& export_dir, const std::string& split);

// The results document: per frame, the tiles' edges whose midpoint lies in them, each
// edge kept by the tile whose centre is nearest to it (overlapping crops predict a lane
// once); lane ends of different tiles within `join_m` joined; chains between junctions
// and ends as centerlines (confidence: the mean of their edge scores, 1 without), cut at
// the window and resampled as the export's; a link where one chain ends and another starts.
nlohmann::ordered_json tiles_to_frame_results(const std::vector<TilePrediction>& tiles, const ExportFrames& frames,
                                              double resolution_m, const std::string& method, double join_m = 1.0);

}  // namespace nsg::frames

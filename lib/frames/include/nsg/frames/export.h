#pragma once
// `nsgraph frames` (docs/frames.md): every key frame of a release whose ego position lies in
// a region of a generated dataset, written as OpenLane-V2's per-frame records
// (`<split>/<scene>/info/<timestamp>.json`: sensor, pose, annotation.lane_centerline,
// annotation.topology_lclc) with its data_dict.json and a manifest (counts, config, the
// leakage figures, sha256 of every file).
#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "nsg/frames/config.h"

namespace nsg::frames {

// Of the test frames' windows, the part a train frame's window covers, by distance from
// the test frame's ego: labels a model has seen in training, farther out the wider the
// window (docs/frames.md "The leakage figure").
struct LeakageBand {
  double from_m = 0.0;  // distance from the ego in [from_m, to_m)
  double to_m = 0.0;
  int64_t window_cells = 0;  // 2.5 m cells of test windows in the band
  int64_t seen_cells = 0;    // of them, inside a train frame's window (same location)
};

// The leakage figure of Lilja et al. (CVPR 2024): how close each test frame's ego position
// comes to a train frame's, within one location; and by_distance, the window cells a train
// frame's window covers.
struct Leakage {
  int64_t test_frames = 0;
  int64_t train_frames = 0;
  int64_t test_within_radius = 0;           // nearer than FramesConfig::leak_radius_m to a train frame
  std::optional<double> share_within;       // test_within_radius / test_frames (none without test frames)
  std::optional<double> median_distance_m;  // over test frames (none without train or test frames)
  std::vector<LeakageBand> by_distance;     // 25 m bands out to the window's farthest corner
};

// Why a key frame of the release is not in the export.
struct DropCounts {
  int64_t other_location = 0;   // its location is not one of the dataset's
  int64_t excluded_scene = 0;   // its scene is in the dataset's scenes.exclude
  int64_t outside_regions = 0;  // its ego position lies in no region
  int64_t overlap = 0;          // its window comes nearer than the buffer to another split's region (overlap: drop)
  int64_t no_ego_pose = 0;      // no LIDAR_TOP key frame to take the pose from
};

struct FramesSummary {
  int64_t key_frames = 0;                                // in the release
  std::map<std::string, std::array<int64_t, 3>> frames;  // location → per split (kSplitNames order)
  DropCounts dropped;
  int64_t flagged_overlap = 0;  // overlap: flag
  int64_t centerlines = 0;      // = lane segments, one per centerline
  int64_t links = 0;
  int64_t lanelines_from_offset = 0;  // lane-segment sides without a divider in the map (frame_map.h)
  int64_t pedestrian_crossings = 0, road_boundaries = 0;  // areas
  Leakage regions;                                        // the dataset's regions
  Leakage scenes_random;                                  // the same frames, split by a seeded draw per scene
  int64_t files = 0;
  int64_t bytes = 0;
  double seconds = 0.0;  // building and writing the records (not loading the release)
  int64_t total_frames() const;
};

struct FramesRun {
  std::filesystem::path dataset;  // a generated dataset (its manifest gives regions, map graph options, release)
  std::filesystem::path out;
  bool overwrite = false;
  bool stats_only = false;  // count and measure, write nothing
  bool progress = false;
};

// ConfigError / IoError / ParseError / DataError naming the file or key; an existing
// export in `out` is refused unless `overwrite`.
FramesSummary export_frames(const FramesConfig& config, const FramesRun& run);

// The summary as the manifest's "counts" and "leakage" objects (and `--stats`).
nlohmann::ordered_json summary_json(const FramesSummary& s, const FramesConfig& config);

}  // namespace nsg::frames

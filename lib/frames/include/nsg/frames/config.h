#pragma once
// The options of `nsgraph frames` (docs/frames.md), each declared once (nsg/core/options.h):
// the window cut around each key frame, the points of its centerlines, what to do with a
// frame whose window comes near another split, the split preset and the leakage radius.
// Reading a config file, --set, the command's flags, range errors naming the key and its
// source, --print-config, --list-options and schemas/v1/frames-config.schema.json come from
// these declarations.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "nsg/core/options.h"

namespace nsg::frames {

// Named windows: OpenLane-V2's perception range, or the long-range one of the geo-disjoint
// long-range evaluations (x ±100 m, y as OpenLane-V2's). A preset gives the edges a config does
// not set itself.
enum class WindowPreset { kOpenLaneV2, kLongRange };

// The frame's window in the ego frame (x forward, y left), metres. The default is
// OpenLane-V2's perception range: x ∈ [−50, 50] m, y ∈ [−25, 25] m (its `openlanev2/utils.py`
// SD_MAP_RANGE, the range its SD map and ground truth are cut to).
struct WindowM {
  double x_min_m = -50.0;
  double x_max_m = 50.0;
  double y_min_m = -25.0;
  double y_max_m = 25.0;
  WindowPreset preset = WindowPreset::kOpenLaneV2;  // last: WindowM{x_min, x_max, y_min, y_max} stays valid
};

// A frame whose window comes nearer than the split buffer to a region of another split.
enum class OverlapMode { kDrop, kKeep, kFlag };
// Where a frame's split comes from: the dataset's regions (leak-free), or a seeded draw per
// scene (how the official nuScenes split is made; for comparison, it leaks).
enum class SplitPreset { kRegions, kScenesRandom };

struct FramesConfig {
  std::string dataroot;  // "" = the dataset manifest's inputs.dataroot
  WindowM window;
  int centerline_points = 11;
  int lane_segment_points = 10;  // each line of a lane segment (OpenLane-V2 v2.1's 10)
  OverlapMode overlap = OverlapMode::kDrop;
  SplitPreset split_preset = SplitPreset::kRegions;
  double leak_radius_m = 5.0;
  bool copy_images = false;
  uint64_t seed = 1;  // the scenes-random draw

  // The declared checks and what one key cannot say alone (min < max); ConfigError naming the key.
  void validate() const;
};

const options::Table<FramesConfig>& frames_option_table();
options::OrderedJson frames_config_schema();
const char* to_string(OverlapMode mode);
const char* to_string(SplitPreset preset);
// The edges of a preset.
WindowM window_of(WindowPreset preset);

// options::resolve_config's precedence: the defaults, the file ("" = none), each --set
// "key=value", then the flags (--copy-images for "copy_images"); the relations last.
FramesConfig resolve_frames_config(const std::filesystem::path& file, const std::vector<std::string>& settings,
                                   const std::vector<options::FlagValue>& flags = {});

}  // namespace nsg::frames

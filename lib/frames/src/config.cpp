// The declarations of the frames options: every key's type, unit, range and description
// in one place.
#include "nsg/frames/config.h"

#include "nsg/core/error.h"

namespace nsg::frames {
namespace {

using options::OrderedJson;
using options::Table;

// A window edge may lie anywhere within OpenLane-V2's range four times over; farther is a
// typo, and it would make every frame cut a quarter of a city.
constexpr double kWindowLimitM = 200.0;

void check_ordered(double lo, double hi, const std::string& lo_key, const std::string& hi_key,
                   const options::Origins& origins) {
  if (lo < hi) return;
  const ConfigError e("", hi_key, "greater than " + lo_key + " (" + std::to_string(lo) + ")");
  options::rethrow_from_origin(e, origins);
}

const Table<WindowM>& window_table() {
  static const Table<WindowM> table = [] {
    Table<WindowM> t;
    const auto edge = [&t](const char* key, double WindowM::*field, const char* what) {
      t.number(key, field).unit("m").range(options::between(-kWindowLimitM, kWindowLimitM)).help(what);
    };
    t.choice("window.preset", &WindowM::preset,
             {{"openlanev2", WindowPreset::kOpenLaneV2}, {"long-range", WindowPreset::kLongRange}})
        .help(
            "The window's edges unless set below: OpenLane-V2's perception range (openlanev2: x ±50 m, y ±25 m) or "
            "the long-range window (long-range: x ±100 m, y ±25 m)");
    edge("window.x_min_m", &WindowM::x_min_m, "Window, ego frame: rearmost x (x forward; OpenLane-V2's range: -50)");
    edge("window.x_max_m", &WindowM::x_max_m, "Window, ego frame: foremost x (OpenLane-V2's range: 50)");
    edge("window.y_min_m", &WindowM::y_min_m, "Window, ego frame: rightmost y (y left; OpenLane-V2's range: -25)");
    edge("window.y_max_m", &WindowM::y_max_m, "Window, ego frame: leftmost y (OpenLane-V2's range: 25)");
    return t;
  }();
  return table;
}

}  // namespace

const char* to_string(OverlapMode mode) {
  switch (mode) {
    case OverlapMode::kDrop: return "drop";
    case OverlapMode::kKeep: return "keep";
    case OverlapMode::kFlag: return "flag";
  }
  return "?";
}

WindowM window_of(WindowPreset preset) {
  WindowM w;
  w.preset = preset;
  if (preset == WindowPreset::kLongRange) {
    w.x_min_m = -100.0;
    w.x_max_m = 100.0;
  }
  return w;
}

const char* to_string(SplitPreset preset) { return preset == SplitPreset::kRegions ? "regions" : "scenes-random"; }

const Table<FramesConfig>& frames_option_table() {
  static const Table<FramesConfig> table = [] {
    Table<FramesConfig> t;
    options::schema_version_option(t);
    t.text("dataroot", &FramesConfig::dataroot)
        .help("The nuScenes release (\"\" = the one the dataset was generated from, its manifest's inputs.dataroot)");
    t.include(&FramesConfig::window, window_table());
    t.integer("centerline_points", &FramesConfig::centerline_points)
        .range(options::between(2, 1000))
        .help(
            "Points of each centerline's `points`, evenly spaced along its length (11: OpenLane-V2's evaluated "
            "ground truth); `points_2m` keeps the lane graph's nodes, at most 2 m apart");
    t.integer("lane_segment_points", &FramesConfig::lane_segment_points)
        .range(options::between(2, 1000))
        .help(
            "Points of each lane segment's centerline, left and right laneline, evenly spaced along each (10: "
            "OpenLane-V2 v2.1's lane segments)");
    t.choice("overlap", &FramesConfig::overlap,
             {{"drop", OverlapMode::kDrop}, {"keep", OverlapMode::kKeep}, {"flag", OverlapMode::kFlag}})
        .help(
            "A frame whose window comes nearer than the split buffer to a region of another split: left out (drop), "
            "kept (keep) or kept and marked `overlap: true` (flag); counted in the manifest");
    t.choice("split_preset", &FramesConfig::split_preset,
             {{"regions", SplitPreset::kRegions}, {"scenes-random", SplitPreset::kScenesRandom}})
        .help(
            "Each frame's split: the dataset region its ego position lies in (regions), or a seeded draw per scene "
            "with the dataset's split ratios, as the official nuScenes split is made (scenes-random: it leaks)");
    t.number("leak_radius_m", &FramesConfig::leak_radius_m)
        .unit("m")
        .range(options::above_up_to(0, 1000))
        .help("Leakage figure: a test frame within this distance of a train frame's ego position counts as seen");
    t.boolean("copy_images", &FramesConfig::copy_images)
        .help("Copy each camera image next to the frame records (a hard link where the file system allows)");
    t.integer("seed", &FramesConfig::seed).range(options::at_least(0)).help("Seed of the scenes-random draw");
    return t;
  }();
  return table;
}

void FramesConfig::validate() const {
  frames_option_table().check(*this);
  check_ordered(window.x_min_m, window.x_max_m, "window.x_min_m", "window.x_max_m", {});
  check_ordered(window.y_min_m, window.y_max_m, "window.y_min_m", "window.y_max_m", {});
}

OrderedJson frames_config_schema() {
  return options::config_schema(
      frames_option_table().specs(), "https://nuscenesgraph.org/schemas/v1/frames-config.schema.json",
      "NuScenesGraph frames config (v1)",
      "Options of `nsgraph frames` (per-key-frame export). A file may give any subset of the keys; the others keep "
      "their defaults. Generated from the options' declarations: `nsgraph frames --list-options --format schema`.");
}

FramesConfig resolve_frames_config(const std::filesystem::path& file, const std::vector<std::string>& settings,
                                   const std::vector<options::FlagValue>& flags) {
  options::Origins origins;
  FramesConfig c = options::resolve_config(frames_option_table(), file, settings, flags, "window.x_max_m=60", origins);
  // The preset's edges where no source set an edge itself.
  const WindowM preset = window_of(c.window.preset);
  const auto from_preset = [&](const char* key, double WindowM::*edge) {
    if (!origins.count(key)) c.window.*edge = preset.*edge;
  };
  from_preset("window.x_min_m", &WindowM::x_min_m);
  from_preset("window.x_max_m", &WindowM::x_max_m);
  from_preset("window.y_min_m", &WindowM::y_min_m);
  from_preset("window.y_max_m", &WindowM::y_max_m);
  check_ordered(c.window.x_min_m, c.window.x_max_m, "window.x_min_m", "window.x_max_m", origins);
  check_ordered(c.window.y_min_m, c.window.y_max_m, "window.y_min_m", "window.y_max_m", origins);
  return c;
}

}  // namespace nsg::frames

// Explains a plan that ends with no tiles (or a split without tiles) from the counts the
// region and crop planners return: which filter took the candidates, how many, and which
// config value to change.
#include <algorithm>
#include <array>
#include <cmath>
#include <set>

#include "nsg/core/strings.h"
#include "plan.h"

namespace nsg::pipeline {

namespace {

// What to suggest at the end, gathered while the accounts are written.
struct Hints {
  bool keep_scenes = false;                   // every scene of a location excluded
  double best_coverage = 0.0;                 // highest coverage among windows below the threshold
  bool more_random = false;                   // random placement asked for 0 crops in a region
  std::set<std::string> explicit_regions;     // locations where a split got no automatic block
  bool bigger_regions = false;                // regions or blocks too small for a crop
  bool block_coverage = false;                // every automatic block below min_block_coverage
  const TimeSplitSides* move_date = nullptr;  // a side of a before-after split has no scene
};

long long ll(int64_t v) { return static_cast<long long>(v); }

double ratio_of(const GenerateConfig& c, size_t k) {
  return k == 0 ? c.splits.ratios.train : k == 1 ? c.splits.ratios.val : c.splits.ratios.test;
}

tiling::Placement placement_of(const GenerateConfig& c, size_t k) {
  return k == 0 ? c.crops.train : k == 1 ? c.crops.val : c.crops.test;
}

// Whether the config asks for tiles of split k at this location.
bool split_asked(const PlanFilters& f, const GenerateConfig& c, size_t k) {
  if (f.time_split) return k != 1;  // before-after: train and test, never val
  if (f.regions.explicit_regions) return f.crops.splits[k].regions > 0;
  return ratio_of(c, k) > 0.0;
}

// One split of one location: its regions and what became of its candidate windows.
std::string split_account(const PlanFilters& f, const GenerateConfig& c, size_t k, Hints& h) {
  const tiling::SplitCropStats& s = f.crops.splits[k];
  const std::string split(tiling::kSplitNames[k]);
  if (s.regions == 0) {
    std::string why;
    if (f.time_split) {
      const TimeSplitSides& t = *f.time_split;
      const bool side_empty = (k == 0 ? t.before : t.after) == 0;
      why = side_empty ? strprintf("no scene captured %s %s", k == 0 ? "before" : "on or after", c.split_date.c_str())
                       : "its scenes kept no LiDAR point";
      if (side_empty) h.move_date = &t;
    } else if (f.regions.explicit_regions) {
      why = "splits.regions." + f.location + " names none";
    } else if (f.regions.no_lidar) {
      why = "no LiDAR to split";
    } else if (ratio_of(c, k) == 0.0) {
      why = "splits.ratios." + split + " is 0";
    } else if (f.regions.blocks_assigned[k] == 0) {
      const int64_t usable = f.regions.blocks - f.regions.blocks_low_coverage;
      why = strprintf("the automatic split made %lld block(s) of %.1f m with enough LiDAR and gave none to %s",
                      ll(usable), f.regions.block_size_m, split.c_str());
      if (split == "test" && usable < 2) why += " (a test block needs at least 2 blocks)";
      h.explicit_regions.insert(f.location);
    } else {
      why = strprintf(
          "its %lld block(s) are smaller than a %.1f m crop once the %.1f m buffers to other splits are cut off",
          ll(f.regions.blocks_too_small[k]), c.crop_size_m(), c.splits.buffer_m);
      h.bigger_regions = true;
    }
    return split + ": no region (" + why + ")";
  }
  std::string line =
      strprintf("%s: %lld region(s) with %.4f km² of LiDAR", split.c_str(), ll(s.regions), s.covered_km2);
  if (s.regions_no_room > 0) {
    line += strprintf("; %lld without room for a %d-px crop", ll(s.regions_no_room), c.crops.size_px);
    h.bigger_regions = true;
  }
  if (s.regions_none_wanted > 0) {
    line += strprintf(
        "; %lld where random placement asks for 0 crops (covered km² × crops.random_per_km2 = %g rounds to 0)",
        ll(s.regions_none_wanted), c.crops.random_per_km2);
    h.more_random = true;
  }
  if (placement_of(c, k) == tiling::Placement::kRandom && s.wanted > 0)
    line += strprintf("; %lld random crop(s) wanted", ll(s.wanted));
  line += strprintf("; %lld candidate window(s) tested, %lld below crops.min_lidar_coverage = %g", ll(s.windows),
                    ll(s.below_coverage), c.crops.min_lidar_coverage);
  if (s.below_coverage > 0) {
    line += strprintf(" (best of them %.3f)", s.best_rejected_coverage);
    h.best_coverage = std::max(h.best_coverage, s.best_rejected_coverage);
  }
  line += strprintf("; %lld kept", ll(s.kept));
  return line;
}

// The location's lines: scenes, the automatic split (if any), then the splits asked for.
std::vector<std::string> location_account(const PlanFilters& f, const GenerateConfig& c, Hints& h,
                                          const std::vector<size_t>& splits) {
  std::vector<std::string> lines;
  std::string head = strprintf("%s: %zu scene(s) used", f.location.c_str(), f.scenes_used);
  if (f.scenes_excluded > 0) head += strprintf(", %zu left out by scenes.exclude", f.scenes_excluded);
  if (f.scenes_used == 0) {
    head += " (every scene of the location is excluded)";
    h.keep_scenes = f.scenes_excluded > 0;
  }
  if (f.regions.no_lidar && f.scenes_used > 0)
    head += strprintf("; no LiDAR point kept (lidar.channel = %s, lidar.max_range_m = %g)",
                      c.raster.lidar_channel.c_str(), c.raster.lidar.max_range_m);
  if (f.time_split) {
    const TimeSplitSides& t = *f.time_split;
    head += strprintf("; before-after split at %s: %zu scene(s) before (train), %zu on or after (test)",
                      c.split_date.c_str(), t.before, t.after);
    if (!t.first_date.empty()) head += ", captured " + t.first_date + " … " + t.last_date;
  } else if (!f.regions.explicit_regions && !f.regions.no_lidar) {
    head += strprintf(
        "; automatic split: %lld block(s) of %.1f m over the LiDAR extent, %lld below "
        "splits.min_block_coverage = %g, assigned %lld train / %lld val / %lld test",
        ll(f.regions.blocks), f.regions.block_size_m, ll(f.regions.blocks_low_coverage), c.splits.min_block_coverage,
        ll(f.regions.blocks_assigned[0]), ll(f.regions.blocks_assigned[1]), ll(f.regions.blocks_assigned[2]));
    if (f.regions.blocks > 0 && f.regions.blocks_low_coverage == f.regions.blocks) h.block_coverage = true;
  }
  lines.push_back(head);
  if (f.regions.no_lidar) return lines;
  for (size_t k : splits)
    if (split_asked(f, c, k) || f.crops.splits[k].regions > 0) lines.push_back("  " + split_account(f, c, k, h));
  return lines;
}

std::vector<std::string> suggestions(const Hints& h, const GenerateConfig& c) {
  std::vector<std::string> out;
  if (h.keep_scenes) out.push_back("keep the excluded scenes: --set 'scenes.exclude=[]'");
  if (h.best_coverage > 0.0) {
    const double lower = std::max(0.01, std::floor(h.best_coverage * 100.0) / 100.0);
    if (lower < c.crops.min_lidar_coverage)
      out.push_back(
          strprintf("accept sparser crops: --set crops.min_lidar_coverage=%.2f (now %g; the best rejected "
                    "window had %.3f)",
                    lower, c.crops.min_lidar_coverage, h.best_coverage));
  }
  if (h.more_random)
    out.push_back(
        strprintf("ask for more random crops: --set crops.random_total=N (per location, over the split's "
                  "regions) or a crops.random_per_km2 above %g",
                  c.crops.random_per_km2));
  if (!h.explicit_regions.empty()) {
    std::vector<std::string> keys;
    for (const std::string& l : h.explicit_regions) keys.push_back("splits.regions." + l);
    out.push_back("give the split regions of its own: " + join(keys, ", ") +
                  " in a --config file (see samples/generate-demo.json), or a smaller splits.block_size_m");
  }
  if (h.bigger_regions)
    out.push_back(
        strprintf("make regions hold a crop: larger regions or splits.block_size_m, a smaller splits.buffer_m "
                  "(now %g m, at least one crop), or smaller crops.size_px (now %d)",
                  c.splits.buffer_m, c.crops.size_px));
  if (h.move_date)
    out.push_back(
        strprintf("move splits.before_after_date (now %s) inside the capture dates (%s … %s) so both "
                  "sides have scenes",
                  c.split_date.c_str(), h.move_date->first_date.c_str(), h.move_date->last_date.c_str()));
  if (h.block_coverage)
    out.push_back(strprintf("let sparser blocks take part: --set splits.min_block_coverage=… (now %g)",
                            c.splits.min_block_coverage));
  return out;
}

}  // namespace

std::string explain_empty_plan(const std::vector<PlanFilters>& filters, const GenerateConfig& config) {
  Hints h;
  std::vector<std::string> lines;
  for (const PlanFilters& f : filters) {
    std::vector<std::string> more = location_account(f, config, h, {0, 1, 2});
    lines.insert(lines.end(), more.begin(), more.end());
  }
  if (filters.empty()) lines.push_back("no location was planned");
  std::string message = "the dataset would hold no tiles (0 train / 0 val / 0 test). Where the candidate crops went:";
  for (const std::string& l : lines) message += "\n  " + l;
  message += "\nWhat to change:";
  for (const std::string& s : suggestions(h, config)) message += "\n  - " + s;
  message += "\n  - or write the empty dataset anyway: --allow-empty";
  return message;
}

std::vector<std::string> empty_split_warnings(const std::vector<PlanFilters>& filters, const GenerateConfig& config) {
  std::array<int64_t, 3> tiles{};
  for (const PlanFilters& f : filters)
    for (size_t k = 0; k < 3; ++k) tiles[k] += f.crops.splits[k].kept;
  const int64_t total = tiles[0] + tiles[1] + tiles[2];
  std::vector<std::string> out;
  if (total == 0) return out;
  for (size_t k = 0; k < 3; ++k) {
    if (tiles[k] > 0) continue;
    const bool asked =
        std::any_of(filters.begin(), filters.end(), [&](const PlanFilters& f) { return split_asked(f, config, k); });
    if (!asked) continue;
    Hints h;
    std::string message = strprintf(
        "the %s split has no tiles (train %lld, val %lld, test %lld):", std::string(tiling::kSplitNames[k]).c_str(),
        ll(tiles[0]), ll(tiles[1]), ll(tiles[2]));
    for (const PlanFilters& f : filters) {
      if (!split_asked(f, config, k)) continue;
      for (const std::string& l : location_account(f, config, h, {k})) message += "\n  " + l;
    }
    const std::vector<std::string> s = suggestions(h, config);
    if (!s.empty()) message += "\n  to change that: " + join(s, "; ");
    out.push_back(message);
  }
  return out;
}

}  // namespace nsg::pipeline

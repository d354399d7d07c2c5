#pragma once
// The leakage figure of Lilja et al., "Localization Is All You Evaluate" (CVPR 2024): for
// every test frame, the distance from its ego position to the nearest train frame's in the
// same location; the share nearer than a radius and the median. And the same question for
// what a frame labels rather than where it stands: the share of the test frames' windows
// that lies inside a train frame's window, per 25 m band of distance from the ego — the
// label leakage a long-range window adds.
#include <string>
#include <vector>

#include "nsg/frames/export.h"

namespace nsg::frames {

struct EgoPosition {
  std::string location;
  double x_m = 0.0;
  double y_m = 0.0;
  int split = 0;         // kSplitNames index: 0 train, 1 val, 2 test
  double yaw_rad = 0.0;  // heading of the ego x axis, counter-clockwise from the map's x
};

inline constexpr double kLeakageBandM = 25.0;
inline constexpr double kLeakageCellM = 2.5;

// Both figures; `window` is every frame's (the export's).
Leakage measure_leakage(const std::vector<EgoPosition>& frames, double radius_m, const WindowM& window);

// by_distance alone: every test frame's window sampled at the centres of kLeakageCellM cells,
// each cell counted in its kLeakageBandM band of distance from the ego and as seen when a
// train frame's window (same location) contains it.
std::vector<LeakageBand> window_leakage(const std::vector<EgoPosition>& frames, const WindowM& window);

}  // namespace nsg::frames

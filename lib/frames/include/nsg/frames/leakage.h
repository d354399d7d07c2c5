#pragma once
// The leakage figure of Lilja et al., "Localization Is All You Evaluate" (CVPR 2024): for
// every test frame, the distance from its ego position to the nearest train frame's in the
// same location; the share nearer than a radius and the median.
#include <string>
#include <vector>

#include "nsg/frames/export.h"

namespace nsg::frames {

struct EgoPosition {
  std::string location;
  double x_m = 0.0;
  double y_m = 0.0;
  int split = 0;  // kSplitNames index: 0 train, 1 val, 2 test
};

Leakage measure_leakage(const std::vector<EgoPosition>& frames, double radius_m);

}  // namespace nsg::frames

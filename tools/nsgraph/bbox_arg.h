#pragma once
// `--bbox xmin,ymin,xmax,ymax` (map metres), shared by the inspect commands.
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "nsg/core/error.h"
#include "nsg/core/strings.h"
#include "nsg/graph/clip.h"

namespace nsg::cli {

inline graph::TileBounds parse_bbox(const std::string& text) {
  const std::vector<std::string> parts = split(text, ',');
  if (parts.size() != 4) throw ConfigError("", "--bbox", "expected xmin,ymin,xmax,ymax in metres");
  double v[4];
  for (int i = 0; i < 4; ++i) {
    char* end = nullptr;
    v[i] = std::strtod(parts[i].c_str(), &end);
    if (parts[i].empty() || *end != '\0' || !std::isfinite(v[i]))
      throw ConfigError("", "--bbox", "'" + parts[i] + "' is not a number");
  }
  if (!(v[0] < v[2] && v[1] < v[3])) throw ConfigError("", "--bbox", "expected xmin < xmax and ymin < ymax");
  return {v[0], v[1], v[2], v[3]};
}

}  // namespace nsg::cli

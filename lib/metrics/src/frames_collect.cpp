// The ground truth as the scorer sees it: a record's centerlines as written, its lane
// segments and areas resampled as OpenLane-V2's lane-segment collect() resamples them.
#include <cmath>

#include "nsg/metrics/frames_documents.h"

namespace nsg::metrics {

namespace {

// Rounded to float32 through a call GCC's vectorizer cannot see through (frames_score.cpp
// says why).
[[gnu::noinline]] double float32_of(double v) { return static_cast<double>(static_cast<float>(v)); }

}  // namespace

std::vector<Point3> interpolate_like_collect(const std::vector<Point3>& line, int n) {
  // GEOS (LengthLocationMap, LinearLocation): segment lengths in x, y summed in order; a
  // distance falls in the first segment whose end lies beyond it, at fraction
  // (d − before) / length of that segment; the end beyond the last.
  std::vector<double> seg(line.size() > 0 ? line.size() - 1 : 0);
  double length = 0.0;
  for (size_t k = 0; k < seg.size(); ++k) {
    seg[k] = std::sqrt((line[k + 1][0] - line[k][0]) * (line[k + 1][0] - line[k][0]) +
                       (line[k + 1][1] - line[k][1]) * (line[k + 1][1] - line[k][1]));
    length += seg[k];
  }
  std::vector<Point3> out;
  out.reserve(static_cast<size_t>(n));
  const double step = length / static_cast<double>(n - 1);  // np.linspace: k · step, the last exact
  for (int k = 0; k < n; ++k) {
    const double d = k == n - 1 ? length : static_cast<double>(k) * step;
    Point3 p = d <= 0.0 ? line.front() : line.back();  // GEOS: no distance is the start
    double before = 0.0;
    for (size_t s = 0; d > 0.0 && s < seg.size(); ++s) {
      if (before + seg[s] > d) {
        const double f = (d - before) / seg[s];
        if (f <= 0.0) {
          p = line[s];
        } else {
          for (int c = 0; c < 3; ++c) p[c] = (line[s + 1][c] - line[s][c]) * f + line[s][c];
        }
        break;
      }
      before += seg[s];
    }
    for (double& c : p) c = float32_of(c);
    out.push_back(p);
  }
  return out;
}

FrameCenterlines FrameRecord::truth() const {
  FrameCenterlines out;
  out.lanes.reserve(centerlines.size());
  for (const FrameRecordCenterline& c : centerlines) out.lanes.push_back(c.points);
  out.topology.assign(topology_lclc.begin(), topology_lclc.end());
  if (!has_map_elements()) return out;
  out.has_map_elements = true;
  for (const FrameRecordLaneSegment& s : lane_segments)
    out.segments.push_back({interpolate_like_collect(s.centerline, kLaneSegmentLinePoints),
                            interpolate_like_collect(s.left_laneline, kLaneSegmentLinePoints),
                            interpolate_like_collect(s.right_laneline, kLaneSegmentLinePoints)});
  out.topology_lsls.assign(topology_lsls.begin(), topology_lsls.end());
  for (const FrameRecordArea& a : areas)
    out.areas.push_back({a.category, interpolate_like_collect(a.points, kAreaPoints)});
  return out;
}

}  // namespace nsg::metrics

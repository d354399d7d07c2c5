// OpenLane-V2 results files (metrics::read_frames_results): any bytes either refused with
// issues or read into frames within the limits, which then score (DET_l, TOP_ll, and
// nsgraph's metrics on the frame graphs) against a small fixed ground truth to values in
// [0, 1]. Limits are cut down so one input stays fast under the sanitizers.
#include <cmath>
#include <cstdlib>

#include "fuzz_support.h"
#include "nsg/metrics/frames.h"
#include "nsg/metrics/measure.h"

namespace {

// Two lanes along x at y = 0 and 3.5, the first linked to the second, keyed as the seeds are.
nsg::metrics::FrameSet truth() {
  nsg::metrics::FrameCenterlines f;
  for (double y : {0.0, 3.5}) {
    std::vector<nsg::metrics::Point3> lane;
    for (int i = 0; i <= 10; ++i) lane.push_back({-20.0 + 4.0 * i, y, 0.0});
    f.lanes.push_back(lane);
  }
  f.topology = {0, 1, 0, 0};
  return {{"tok", f}};
}

void in_unit_range(double v) {
  if (!(v >= 0.0 && v <= 1.0)) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  nsg::fuzz::expect_only_input_errors([&] {
    nsg::metrics::FrameResultsLimits limits;
    limits.max_centerlines_per_frame = 40;
    limits.max_points_per_centerline = 60;
    limits.max_points_per_frame = 400;
    limits.max_links_per_frame = 200;
    limits.max_json_values = 20'000;
    nsg::Issues issues;
    const auto pred = nsg::metrics::read_frames_results(nsg::fuzz::input_file(data, size), limits, issues);
    if (!pred) {
      if (issues.empty()) std::abort();  // refused without saying why
      return;
    }
    const nsg::metrics::FrameSet gt = truth();
    nsg::metrics::check_frame_work(gt, *pred, limits, "fuzz", issues);
    if (!issues.empty()) return;
    nsg::metrics::FramesReport r;
    try {
      r = nsg::metrics::score_frames(gt, *pred, /*graph_metrics=*/true);
    } catch (const nsg::metrics::SearchWorkExceeded&) {
      return;  // refused by name, as score_frames_submission does
    }
    for (const double v : {r.det_l, r.top_ll, r.lane_score}) in_unit_range(v);
    for (const auto& [name, value] : r.graph_means)
      if (value) in_unit_range(*value);
  });
  return 0;
}

// Frame records (metrics::read_frame_record, the one reader of <split>/<scene>/info/*.json):
// any bytes either refused by name (ParseError) or read into a record whose shapes hold —
// topology n × n of 0/1, every centerline 2+ finite points, every matrix finite — and whose
// scorer's view (truth()) scores against itself to 1. Limits are cut down so one input stays
// fast under the sanitizers.
#include <cmath>
#include <cstdlib>
#include <string_view>

#include "fuzz_support.h"
#include "nsg/metrics/frames.h"

namespace {

void require(bool ok) {
  if (!ok) std::abort();
}

void finite(const std::array<double, 3>& v) {
  for (const double x : v) require(std::isfinite(x));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  nsg::fuzz::expect_only_input_errors([&] {
    nsg::metrics::FramesDocumentLimits limits;
    limits.max_json_values = 20'000;
    limits.max_centerlines = 40;
    limits.max_points_per_centerline = 60;
    const nsg::metrics::FrameRecord r =
        nsg::metrics::read_frame_record(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz", limits);
    const size_t n = r.centerlines.size();
    require(r.topology_lclc.size() == n * n);
    for (const uint8_t v : r.topology_lclc) require(v == 0 || v == 1);
    for (const auto& c : r.centerlines) {
      require(c.points.size() >= 2 && c.points_2m.size() >= 2);
      for (const auto& p : c.points) finite(p);
      for (const auto& p : c.points_2m) finite(p);
    }
    for (const auto& row : r.pose.rotation) finite(row);
    finite(r.pose.translation);
    for (const auto& cam : r.cameras) require(!cam.image_path.empty() && cam.image_path[0] != '/');
    const nsg::metrics::FrameSet truth = {{r.sample_token, r.truth()}};
    nsg::metrics::FrameSet self = truth;
    for (auto& [key, f] : self) {
      f.confidence.assign(f.lanes.size(), 1.0);
      f.segment_confidence.assign(f.segments.size(), 1.0);
      f.area_confidence.assign(f.areas.size(), 1.0);
    }
    const nsg::metrics::FramesReport s = nsg::metrics::score_frames(truth, self);
    require(s.det_l >= 0.0 && s.det_l <= 1.0 && s.top_ll >= 0.0 && s.top_ll <= 1.0);
    require(!r.has_map_elements() || (s.has_lane_segments && s.det_ls >= 0.0 && s.det_ls <= 1.0 && s.det_a >= 0.0 &&
                                      s.det_a <= 1.0 && s.top_lsls >= 0.0 && s.top_lsls <= 1.0));
  });
  return 0;
}

#pragma once
// A key frame's ground truth (docs/frames.md): the location's lane graph — the very graph
// the tiles are cut from — seen from the ego and cut exactly at the window's edge. Each
// lane or connector whose node chain enters the window gives one centerline per stretch
// inside it; the successor relation links a centerline that reaches its lane's end to one
// that starts at a successor lane's start, so a lane cut in two by the window keeps no link
// between its pieces.
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "nsg/frames/config.h"
#include "nsg/geometry/transform.h"
#include "nsg/graph/lane_graph.h"
#include "nsg/graph/segment_index.h"

namespace nsg::frames {

struct FrameCenterline {
  int64_t id = 0;  // stable along a scene: lane index × 1000 + the piece's ordinal in its lane
  int32_t lane = -1;
  std::string lane_token;
  bool is_connector = false;
  bool starts_at_lane_start = false;  // false: the window cut it there
  bool ends_at_lane_end = false;
  std::vector<Eigen::Vector3d> points_2m;  // the graph's nodes inside, plus the cut points (ego frame, m)
  std::vector<Eigen::Vector3d> points;     // resampled to centerline_points, evenly along the length
};

struct FrameLanes {
  std::vector<FrameCenterline> centerlines;             // by lane index, then along the lane
  std::vector<std::pair<int32_t, int32_t>> successors;  // (from, to) centerline indices, sorted
};

// The map (z = 0 in the global frame, as nuScenes' ego poses are) in the frame of
// `ego_from_global`, clipped to `window` (closed box in ego x, y). Points keep the z the
// pose gives the map plane (0 for a level pose).
FrameLanes cut_frame_lanes(const graph::LaneGraph& graph, const graph::SegmentIndex& index,
                           const geometry::Rigid3& global_from_ego, const WindowM& window, int centerline_points);

// The stretches of one chain (already in the ego frame) inside the window, as centerlines
// of lane `lane` (ids lane × 1000 + ordinal; `points` left empty).
std::vector<FrameCenterline> clip_chain(const std::vector<Eigen::Vector3d>& chain, const WindowM& window, int32_t lane,
                                        const std::string& token, bool is_connector);

// `n` points evenly spaced along the polyline's length (first and last exact); n ≥ 2.
std::vector<Eigen::Vector3d> resample_by_count(const std::vector<Eigen::Vector3d>& polyline, int n);

// The window's corners in the global frame (x, y), counter-clockwise from (x_min, y_min).
std::vector<Eigen::Vector2d> window_corners_global(const geometry::Rigid3& global_from_ego, const WindowM& window);

}  // namespace nsg::frames

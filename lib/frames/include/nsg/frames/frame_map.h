#pragma once
// A key frame's lane segments and areas (docs/frames.md "Lane segments and areas"):
// OpenLane-V2 v2.1's map element bucket, cut from the map expansion the lane graph was
// built from. A lane segment is one centerline of the frame (same id, same order, so
// topology_lsls is topology_lclc) with its left and right lanelines; an area is a
// pedestrian crossing or a stretch of road boundary inside the window.
//
// Lanelines come from the lane's left/right_lane_divider_segments, cut where the
// centerline piece starts and ends. A side without dividers (every lane connector, and a
// lane whose record lists none on that side: real maps have a few) is the centerline moved
// sideways by half the lane's width; a connector's width is the mean width of the lanes it
// joins (at their joined ends), kDefaultLaneWidthM when none has dividers. Such a side
// has line type none and is counted.
#include <cstdint>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "nsg/frames/config.h"
#include "nsg/frames/frame_lanes.h"
#include "nsg/geometry/transform.h"
#include "nsg/graph/lane_graph.h"
#include "nsg/nuscenes/map_expansion.h"

namespace nsg::frames {

// OpenLane-V2's laneline types (left_laneline_type, right_laneline_type).
enum class LineType : int { kNone = 0, kSolid = 1, kDash = 2 };

// nuScenes' divider segment_type → OpenLane-V2's: a type naming SOLID is solid (a
// mixed solid/dashed pair may not be crossed from one side), else one naming DASH is
// dash, anything else ("NIL", "", unknown) none.
LineType line_type_of(std::string_view segment_type);

// Lane width when no lane around a connector has dividers (m): a common urban lane.
inline constexpr double kDefaultLaneWidthM = 3.5;

// A laneline of a whole map lane (global x, y), oriented along the lane; types[k] is the
// type of the stretch from points[k] to points[k + 1].
struct LaneBoundary {
  std::vector<Eigen::Vector2d> points;
  std::vector<LineType> types;
};

// A closed ring of the drivable area (exterior or hole), split into chunks of consecutive
// points with their bounding boxes, so that a frame clips only the chunks near it.
struct BoundaryRing {
  std::vector<Eigen::Vector2d> points;  // closed: the last point equals the first
  struct Chunk {
    size_t first = 0, last = 0;  // point indices, inclusive; consecutive chunks share a point
    Eigen::Vector2d min, max;
  };
  std::vector<Chunk> chunks;
};

// A ring of `points` (global x, y; open or closed), chunked; empty when under 3 points.
BoundaryRing boundary_ring(std::vector<Eigen::Vector2d> points);

// What a location's map gives every frame, built once per location.
struct LocationMapElements {
  std::vector<LaneBoundary> left, right;                    // per graph lane; empty points: none in the map
  std::vector<double> half_width_m;                         // per graph lane: what a side without dividers is moved by
  std::vector<std::vector<Eigen::Vector2d>> ped_crossings;  // exterior rings, open
  std::vector<BoundaryRing> road_boundaries;
};

LocationMapElements location_map_elements(const nuscenes::MapExpansion& map, const graph::LaneGraph& graph);

struct FrameLaneSegment {
  int64_t id = 0;                                                          // the centerline's
  std::vector<Eigen::Vector3d> centerline, left_laneline, right_laneline;  // ego frame, `points` each
  LineType left_type = LineType::kNone, right_type = LineType::kNone;
  bool is_intersection_or_connector = false;
  bool left_from_offset = false, right_from_offset = false;  // no divider on that side
};

enum class AreaCategory : int { kPedestrianCrossing = 1, kRoadBoundary = 2 };

struct FrameArea {
  int64_t id = 0;  // stable along a scene: crossings by map order, boundaries by ring and piece
  AreaCategory category = AreaCategory::kPedestrianCrossing;
  std::vector<Eigen::Vector3d> points;  // ego frame; a crossing's outline closed (last = first)
};

struct FrameMapElements {
  std::vector<FrameLaneSegment> lane_segments;  // one per centerline, same order
  std::vector<FrameArea> areas;                 // crossings first, then road boundaries
};

// The lane segments of `lanes` (cut by cut_frame_lanes from the same graph) and the areas
// inside `window`, each line resampled to `points` points.
FrameMapElements cut_frame_map(const FrameLanes& lanes, const LocationMapElements& map,
                               const geometry::Rigid3& global_from_ego, const WindowM& window, int points);

// The convex-window clip of a closed polygon (ego x, y; Sutherland–Hodgman); empty when
// nothing of it lies inside.
std::vector<Eigen::Vector2d> clip_polygon_to_window(const std::vector<Eigen::Vector2d>& ring, const WindowM& window);

}  // namespace nsg::frames

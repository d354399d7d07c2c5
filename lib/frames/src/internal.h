#pragma once
// Pieces of the frames export shared by its sources (not installed).
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "nsg/frames/frame_lanes.h"
#include "nsg/frames/frame_map.h"
#include "nsg/geometry/transform.h"
#include "nsg/nuscenes/database.h"
#include "nsg/tiling/regions.h"

namespace nsg::frames {

// The frame record's fields that are not the release's (the rest comes from the sample).
struct FrameContext {
  nuscenes::Index sample = nuscenes::kNoIndex;
  std::string split;
  std::string location;
  std::string region;  // "" for a scenes-random split
  std::string map_version;
  bool flag_overlap = false;
  bool overlap = false;
  geometry::Rigid3 global_from_ego;
  std::string image_root;  // "" = image_path relative to the dataroot; else the copy's folder (relative)
};

// Every camera key frame of the sample, in nuScenes' channel order (front, front right,
// front left, back, back left, back right), other camera channels after them by name.
std::vector<nuscenes::Index> camera_key_frames(const nuscenes::Database& db, nuscenes::Index sample);

// The record as OpenLane-V2's info/<timestamp>.json lays it out (docs/frames.md).
// Version 2: the annotation also holds the lane segments and areas (frame_map.h). The
// record's text (compact JSON, a final newline), as nlohmann's dump writes it.
std::string frame_record_text(const nuscenes::Database& db, const FrameContext& context, const FrameLanes& lanes,
                              const FrameMapElements& elements);

// A pose of the release as a rigid transform (target ← source).
geometry::Rigid3 rigid(const nuscenes::Vec3& translation, const geometry::Quaternion& rotation);

// The smallest distance from the convex polygon (global x, y) to the rectangle; 0 when they meet.
double polygon_rect_distance(const std::vector<Eigen::Vector2d>& polygon, const tiling::RectM& rect);

}  // namespace nsg::frames

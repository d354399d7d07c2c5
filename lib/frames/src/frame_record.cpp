// One key frame as OpenLane-V2's per-frame record: its cameras (image, intrinsic, camera →
// ego extrinsic), the ego pose and the annotation (lane centerlines and their topology;
// lane segments, areas and their topology).
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string_view>

#include "internal.h"

namespace nsg::frames {
namespace {

using nlohmann::ordered_json;

// nuScenes' order of the six surround cameras (the devkit's render order).
constexpr std::array<std::string_view, 6> kCameraOrder = {"CAM_FRONT", "CAM_FRONT_RIGHT", "CAM_FRONT_LEFT",
                                                          "CAM_BACK",  "CAM_BACK_LEFT",   "CAM_BACK_RIGHT"};

// Coordinates are written to 0.1 mm: shorter records, and what a reader gets back is what
// it would get from any re-export (the value, not the last bits of a transform).
double rounded_m(double v) { return std::round(v * 1e4) / 1e4; }

ordered_json matrix_json(const Eigen::Matrix3d& m) {
  ordered_json rows = ordered_json::array();
  for (int r = 0; r < 3; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2)});
  return rows;
}

ordered_json vector_json(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

ordered_json transform_json(const geometry::Rigid3& t) {
  return {{"rotation", matrix_json(t.rotation)}, {"translation", vector_json(t.translation)}};
}

ordered_json points_json(const std::vector<Eigen::Vector3d>& points) {
  ordered_json out = ordered_json::array();
  for (const Eigen::Vector3d& p : points) out.push_back({rounded_m(p.x()), rounded_m(p.y()), rounded_m(p.z())});
  return out;
}

int camera_rank(std::string_view channel) {
  const auto it = std::find(kCameraOrder.begin(), kCameraOrder.end(), channel);
  return static_cast<int>(it - kCameraOrder.begin());
}

ordered_json camera_json(const nuscenes::Database& db, nuscenes::Index sd_index, const FrameContext& context) {
  const nuscenes::SampleData& sd = db.sample_data[sd_index];
  const nuscenes::CalibratedSensor& cs = db.calibrated_sensor[sd.calibrated_sensor];
  const nuscenes::EgoPose& pose = db.ego_pose[sd.ego_pose];
  Eigen::Matrix3d k = Eigen::Matrix3d::Zero();
  if (cs.camera_intrinsic)
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) k(r, c) = (*cs.camera_intrinsic)[r][c];
  const std::string image_path = context.image_root.empty()
                                     ? sd.filename
                                     : context.image_root + "/" + db.channel(sd) + "/" +
                                           std::to_string(db.sample[context.sample].timestamp_us) + ".jpg";
  return {{"image_path", image_path},
          {"timestamp", sd.timestamp_us},
          {"width", sd.width},
          {"height", sd.height},
          // camera → ego, the devkit's calibrated_sensor (OpenLane-V2's "extrinsic").
          {"extrinsic", transform_json(rigid(cs.translation, cs.rotation))},
          // nuScenes' images are rectified: no distortion coefficients.
          {"intrinsic", {{"K", matrix_json(k)}, {"distortion", ordered_json::array()}}},
          // The ego at this camera's exposure (it differs from the frame's pose by the
          // motion between sensor times): ego → global.
          {"ego_pose", transform_json(rigid(pose.translation, pose.rotation))}};
}

ordered_json lane_segment_json(const FrameLaneSegment& s) {
  return {{"id", s.id},
          {"centerline", points_json(s.centerline)},
          {"left_laneline", points_json(s.left_laneline)},
          {"left_laneline_type", static_cast<int>(s.left_type)},
          {"right_laneline", points_json(s.right_laneline)},
          {"right_laneline_type", static_cast<int>(s.right_type)},
          {"is_intersection_or_connector", s.is_intersection_or_connector}};
}

ordered_json annotation_json(const FrameLanes& lanes, const FrameMapElements& elements) {
  ordered_json centerlines = ordered_json::array();
  for (const FrameCenterline& c : lanes.centerlines)
    centerlines.push_back({{"id", c.id},
                           {"points", points_json(c.points)},
                           {"points_2m", points_json(c.points_2m)},
                           {"is_intersection_or_connector", c.is_connector},
                           {"lane_token", c.lane_token},
                           {"starts_at_lane_start", c.starts_at_lane_start},
                           {"ends_at_lane_end", c.ends_at_lane_end}});
  const size_t n = lanes.centerlines.size();
  std::vector<std::vector<int>> matrix(n, std::vector<int>(n, 0));
  for (const auto& [from, to] : lanes.successors) matrix[static_cast<size_t>(from)][static_cast<size_t>(to)] = 1;
  ordered_json topology = ordered_json::array();
  ordered_json lcte = ordered_json::array();
  for (const std::vector<int>& row : matrix) {
    topology.push_back(row);
    lcte.push_back(ordered_json::array());  // n × 0: nuScenes has no traffic elements
  }
  ordered_json segments = ordered_json::array();
  for (const FrameLaneSegment& s : elements.lane_segments) segments.push_back(lane_segment_json(s));
  ordered_json areas = ordered_json::array();
  for (const FrameArea& a : elements.areas)
    areas.push_back({{"id", a.id}, {"category", static_cast<int>(a.category)}, {"points", points_json(a.points)}});
  // Lane segments are the centerlines with their lanelines: one topology for both.
  return {{"lane_centerline", centerlines}, {"traffic_element", ordered_json::array()},
          {"topology_lclc", topology},      {"topology_lcte", lcte},
          {"lane_segment", segments},       {"area", areas},
          {"topology_lsls", topology},      {"topology_lste", lcte}};
}

}  // namespace

geometry::Rigid3 rigid(const nuscenes::Vec3& translation, const geometry::Quaternion& rotation) {
  return geometry::Rigid3::from_pose(translation, rotation);
}

std::vector<nuscenes::Index> camera_key_frames(const nuscenes::Database& db, nuscenes::Index sample) {
  std::vector<nuscenes::Index> out;
  for (const nuscenes::SampleDataRef& ref : db.sample[sample].data)
    if (db.sample_data[ref.sample_data].modality == nuscenes::Modality::kCamera) out.push_back(ref.sample_data);
  std::sort(out.begin(), out.end(), [&](nuscenes::Index a, nuscenes::Index b) {
    const std::string& ca = db.channel(db.sample_data[a]);
    const std::string& cb = db.channel(db.sample_data[b]);
    const int ra = camera_rank(ca), rb = camera_rank(cb);
    return ra != rb ? ra < rb : ca < cb;
  });
  return out;
}

nlohmann::ordered_json frame_record(const nuscenes::Database& db, const FrameContext& context, const FrameLanes& lanes,
                                    const FrameMapElements& elements) {
  const nuscenes::Sample& sample = db.sample[context.sample];
  const nuscenes::Scene& scene = db.scene[sample.scene];
  ordered_json sensors = ordered_json::object();
  for (const nuscenes::Index sd : camera_key_frames(db, context.sample))
    sensors[db.channel(db.sample_data[sd])] = camera_json(db, sd, context);
  ordered_json record = {{"schema_version", "1"},
                         {"version", "nsgraph-frames-2"},
                         {"segment_id", scene.name},
                         {"meta_data",
                          {{"source", "nuscenes"},
                           {"source_id", scene.token.str()},
                           {"version", db.version()},
                           {"location", context.location},
                           {"map_version", context.map_version},
                           {"region", context.region.empty() ? ordered_json(nullptr) : ordered_json(context.region)}}},
                         {"timestamp", sample.timestamp_us},
                         {"sample_token", sample.token.str()},
                         {"split", context.split},
                         {"sensor", sensors},
                         // The ego at the LIDAR_TOP key frame (the sample's time): ego → global.
                         {"pose", transform_json(context.global_from_ego)},
                         {"annotation", annotation_json(lanes, elements)}};
  if (context.flag_overlap) record["overlap"] = context.overlap;
  return record;
}

double polygon_rect_distance(const std::vector<Eigen::Vector2d>& polygon, const tiling::RectM& rect) {
  const std::vector<Eigen::Vector2d> box = {{rect.x_west_m, rect.y_south_m},
                                            {rect.x_east_m, rect.y_south_m},
                                            {rect.x_east_m, rect.y_north_m},
                                            {rect.x_west_m, rect.y_north_m}};
  // Inside tests: a polygon vertex in the box, or a box corner in the (convex) polygon.
  for (const Eigen::Vector2d& p : polygon)
    if (p.x() >= rect.x_west_m && p.x() <= rect.x_east_m && p.y() >= rect.y_south_m && p.y() <= rect.y_north_m)
      return 0.0;
  const auto inside_polygon = [&](const Eigen::Vector2d& q) {
    int sign = 0;
    for (size_t i = 0; i < polygon.size(); ++i) {
      const Eigen::Vector2d& a = polygon[i];
      const Eigen::Vector2d& b = polygon[(i + 1) % polygon.size()];
      const double cross = (b.x() - a.x()) * (q.y() - a.y()) - (b.y() - a.y()) * (q.x() - a.x());
      const int s = cross > 0 ? 1 : (cross < 0 ? -1 : 0);
      if (s != 0 && sign != 0 && s != sign) return false;
      if (s != 0) sign = s;
    }
    return true;
  };
  for (const Eigen::Vector2d& q : box)
    if (inside_polygon(q)) return 0.0;
  // Apart or crossing edges: the distance between the two outlines (0 where edges cross).
  const auto point_segment = [](const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    const Eigen::Vector2d d = b - a;
    const double len2 = d.squaredNorm();
    const double t = len2 > 0.0 ? std::clamp((p - a).dot(d) / len2, 0.0, 1.0) : 0.0;
    return (a + d * t - p).norm();
  };
  const auto crosses = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                          const Eigen::Vector2d& d) {
    const auto orient = [](const Eigen::Vector2d& p, const Eigen::Vector2d& q, const Eigen::Vector2d& r) {
      return (q.x() - p.x()) * (r.y() - p.y()) - (q.y() - p.y()) * (r.x() - p.x());
    };
    return orient(a, b, c) * orient(a, b, d) <= 0 && orient(c, d, a) * orient(c, d, b) <= 0;
  };
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < polygon.size(); ++i) {
    const Eigen::Vector2d& a = polygon[i];
    const Eigen::Vector2d& b = polygon[(i + 1) % polygon.size()];
    for (size_t j = 0; j < box.size(); ++j) {
      const Eigen::Vector2d& c = box[j];
      const Eigen::Vector2d& d = box[(j + 1) % box.size()];
      if (crosses(a, b, c, d)) return 0.0;
      best = std::min(
          {best, point_segment(a, c, d), point_segment(b, c, d), point_segment(c, a, b), point_segment(d, a, b)});
    }
  }
  return best;
}

}  // namespace nsg::frames

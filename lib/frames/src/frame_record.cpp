// One key frame as OpenLane-V2's per-frame record: its cameras (image, intrinsic, camera →
// ego extrinsic), the ego pose and the annotation (lane centerlines and their topology;
// lane segments, areas and their topology).
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <limits>
#include <string_view>
#include <type_traits>

#include "internal.h"
#include "nsg/metrics/frames_documents.h"

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

// The annotation's text, written directly: it is most of a record (tens of thousands of
// numbers), and a JSON tree of it cost more than everything else the export does. The
// output is what nlohmann's dump gives for the same values (numbers in the shortest form
// that reads back, integral ones with ".0").
class AnnotationWriter {
 public:
  std::string take() { return std::move(out_); }

  void key(std::string_view name) {
    out_ += '"';
    out_ += name;
    out_ += "\":";
  }
  void number(double v) {
    char buf[64];
    const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed);
    out_.append(buf, r.ptr);
    if (std::string_view(buf, static_cast<size_t>(r.ptr - buf)).find('.') == std::string_view::npos) out_ += ".0";
  }
  void integer(int64_t v) { out_ += std::to_string(v); }
  void boolean(bool v) { out_ += v ? "true" : "false"; }
  void text(const std::string& v) { out_ += ordered_json(v).dump(); }
  // Coordinates to 0.1 mm: shorter records, and what a reader gets back is what it would get
  // from any re-export (the value, not the last bits of a transform).
  void points(const std::vector<Eigen::Vector3d>& points) {
    out_ += '[';
    for (size_t k = 0; k < points.size(); ++k) {
      if (k > 0) out_ += ',';
      out_ += '[';
      for (int c = 0; c < 3; ++c) {
        if (c > 0) out_ += ',';
        number(rounded_m(points[k][c]));
      }
      out_ += ']';
    }
    out_ += ']';
  }
  // n × n of 0/1 from the (from, to) pairs.
  void matrix(size_t n, const std::vector<std::pair<int32_t, int32_t>>& ones) {
    std::vector<uint8_t> m(n * n, 0);
    for (const auto& [from, to] : ones) m[static_cast<size_t>(from) * n + static_cast<size_t>(to)] = 1;
    out_ += '[';
    for (size_t i = 0; i < n; ++i) {
      if (i > 0) out_ += ',';
      out_ += '[';
      for (size_t j = 0; j < n; ++j) {
        if (j > 0) out_ += ',';
        out_ += m[i * n + j] ? '1' : '0';
      }
      out_ += ']';
    }
    out_ += ']';
  }
  // n × 0: a row per lane, no traffic element.
  void empty_rows(size_t n) {
    out_ += '[';
    for (size_t i = 0; i < n; ++i) out_ += i > 0 ? ",[]" : "[]";
    out_ += ']';
  }
  void raw(std::string_view s) { out_ += s; }
  // `"name":value` inside an object, after a comma unless it is the object's first member.
  template <typename T>
  void member(std::string_view name, const T& value) {
    if (out_.back() != '{') out_ += ',';
    key(name);
    if constexpr (std::is_same_v<T, bool>) boolean(value);
    else if constexpr (std::is_same_v<T, int64_t>) integer(value);
    else if constexpr (std::is_same_v<T, std::string>) text(value);
    else points(value);
  }

 private:
  std::string out_;
};

void write_centerline(AnnotationWriter& w, const FrameCenterline& c) {
  w.raw("{");
  w.member("id", c.id);
  w.member("points", c.points);
  w.member("points_2m", c.points_2m);
  w.member("is_intersection_or_connector", c.is_connector);
  w.member("lane_token", c.lane_token);
  w.member("starts_at_lane_start", c.starts_at_lane_start);
  w.member("ends_at_lane_end", c.ends_at_lane_end);
  w.raw("}");
}

void write_lane_segment(AnnotationWriter& w, const FrameLaneSegment& s) {
  w.raw("{");
  w.member("id", s.id);
  w.member("centerline", s.centerline);
  w.member("left_laneline", s.left_laneline);
  w.member("left_laneline_type", static_cast<int64_t>(s.left_type));
  w.member("right_laneline", s.right_laneline);
  w.member("right_laneline_type", static_cast<int64_t>(s.right_type));
  w.member("is_intersection_or_connector", s.is_intersection_or_connector);
  w.raw("}");
}

void write_area(AnnotationWriter& w, const FrameArea& a) {
  w.raw("{");
  w.member("id", a.id);
  w.member("category", static_cast<int64_t>(a.category));
  w.member("points", a.points);
  w.raw("}");
}

template <typename T, typename Write>
void write_list(AnnotationWriter& w, std::string_view name, const std::vector<T>& items, Write write) {
  w.key(name);
  w.raw("[");
  for (size_t k = 0; k < items.size(); ++k) {
    if (k > 0) w.raw(",");
    write(w, items[k]);
  }
  w.raw("]");
}

// Lane segments are the centerlines with their lanelines: one topology for both.
std::string annotation_text(const FrameLanes& lanes, const FrameMapElements& elements) {
  const size_t n = lanes.centerlines.size();
  AnnotationWriter w;
  w.raw("{");
  write_list(w, "lane_centerline", lanes.centerlines, write_centerline);
  w.raw(",");
  w.key("traffic_element");
  w.raw("[],");  // nuScenes has no traffic elements
  w.key("topology_lclc");
  w.matrix(n, lanes.successors);
  w.raw(",");
  w.key("topology_lcte");
  w.empty_rows(n);
  w.raw(",");
  write_list(w, "lane_segment", elements.lane_segments, write_lane_segment);
  w.raw(",");
  write_list(w, "area", elements.areas, write_area);
  w.raw(",");
  w.key("topology_lsls");
  w.matrix(n, lanes.successors);
  w.raw(",");
  w.key("topology_lste");
  w.empty_rows(n);
  w.raw("}");
  return w.take();
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

std::string frame_record_text(const nuscenes::Database& db, const FrameContext& context, const FrameLanes& lanes,
                              const FrameMapElements& elements) {
  const nuscenes::Sample& sample = db.sample[context.sample];
  const nuscenes::Scene& scene = db.scene[sample.scene];
  ordered_json sensors = ordered_json::object();
  for (const nuscenes::Index sd : camera_key_frames(db, context.sample))
    sensors[db.channel(db.sample_data[sd])] = camera_json(db, sd, context);
  ordered_json record = {{"schema_version", "1"},
                         {"version", metrics::kFrameRecordVersion},
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
                         {"annotation", nullptr}};
  // The annotation is written by AnnotationWriter and set in place of the null.
  std::string text = record.dump();
  const std::string slot = "\"annotation\":null";
  const size_t at = text.rfind(slot);
  text.replace(at, slot.size(), "\"annotation\":" + annotation_text(lanes, elements));
  if (context.flag_overlap) {
    text.pop_back();  // the closing brace
    text += std::string(",\"overlap\":") + (context.overlap ? "true" : "false") + "}";
  }
  return text + "\n";
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

// An OpenLane-V2 results document, a stranger's file: size checked before it is read,
// parsed strictly (frames_json.h), every value checked and named by its JSON pointer.
#include <algorithm>
#include <cmath>

#include "frames_json.h"
#include "nsg/metrics/frames.h"
#include "nsg/validate/submission.h"

namespace nsg::metrics {
namespace {

using simdjson::dom::array;
using simdjson::dom::element;
using simdjson::dom::object;

class ResultsReader {
 public:
  ResultsReader(std::string label, const FrameResultsLimits& limits, Issues& issues)
      : label_(std::move(label)), limits_(limits), issues_(issues) {}

  std::optional<FrameSet> read(element doc) {
    object top, results;
    element r;
    if (doc.get_object().get(top) || top.at_key("results").get(r) || r.get_object().get(results)) {
      problem("frames.results.schema", "",
              "an object with \"results\": {sample token or split/segment_id/timestamp: {\"predictions\": …}}");
      return std::nullopt;
    }
    FrameSet out;
    for (const auto field : results) {
      const std::string token(field.key);
      const std::string at = "/results/" + validate::json_pointer_token(token);
      FrameCenterlines f;
      if (frame(field.value, at, f)) out.emplace_back(token, std::move(f));
    }
    if (!ok_) return std::nullopt;
    return out;
  }

 private:
  void problem(const char* check, const std::string& at, const std::string& expected) {
    issues_.error(check, label_ + ":" + at, "expected " + expected);
    ok_ = false;
  }

  bool frame(element entry, const std::string& at, FrameCenterlines& f) {
    object p;
    element predictions;
    if (entry.at_key("predictions").get(predictions) || predictions.get_object().get(p)) {
      problem("frames.results.schema", at, "{\"predictions\": {\"lane_centerline\": […], \"topology_lclc\": […]}}");
      return false;
    }
    element segments_e;
    const bool has_segments = p.at_key("lane_segment").get(segments_e) == simdjson::SUCCESS;
    element lanes_e;
    if (has_segments && p.at_key("lane_centerline").get(lanes_e) != simdjson::SUCCESS) {
      f.has_centerlines = false;  // a lane-segment submission (LaneSegNet's)
    } else if (!centerlines(p, at, f)) {
      return false;
    }
    return !has_segments || map_elements(p, segments_e, at, f);
  }

  bool centerlines(const object& p, const std::string& at, FrameCenterlines& f) {
    array lanes;
    element lanes_e;
    if (p.at_key("lane_centerline").get(lanes_e) || lanes_e.get_array().get(lanes)) {
      problem("frames.results.schema", at + "/predictions/lane_centerline", "an array of centerlines");
      return false;
    }
    if (!within_count(lanes.size(), at + "/predictions/lane_centerline", "centerlines")) return false;
    int64_t points = 0;
    size_t i = 0;
    for (const element lane : lanes)
      if (!centerline(lane, at + "/predictions/lane_centerline/" + std::to_string(i++), f, &points)) return false;
    if (points > limits_.max_points_per_frame) {
      problem("frames.results.size", at + "/predictions/lane_centerline",
              "at most " + std::to_string(limits_.max_points_per_frame) + " points in a frame (got " +
                  std::to_string(points) + ")");
      return false;
    }
    element topology_e;
    if (p.at_key("topology_lclc").get(topology_e)) {
      problem("frames.results.schema", at + "/predictions/topology_lclc",
              std::to_string(f.lanes.size()) + " × " + std::to_string(f.lanes.size()) + " probabilities in [0, 1]");
      return false;
    }
    if (!topology(topology_e, at + "/predictions/topology_lclc", f.lanes.size(), f.topology)) return false;
    const int64_t links = std::count_if(f.topology.begin(), f.topology.end(), [](double v) { return v > 0.5; });
    if (links > limits_.max_links_per_frame) {
      problem("frames.results.size", at + "/predictions/topology_lclc",
              "at most " + std::to_string(limits_.max_links_per_frame) + " links above 0.5 in a frame (got " +
                  std::to_string(links) + ")");
      return false;
    }
    return true;
  }

  bool within_count(size_t n, const std::string& at, const char* what) {
    if (static_cast<int64_t>(n) <= limits_.max_centerlines_per_frame) return true;
    problem("frames.results.size", at,
            "at most " + std::to_string(limits_.max_centerlines_per_frame) + " " + what + " (got " + std::to_string(n) +
                ")");
    return false;
  }

  // OpenLane-V2 v2.1's lane segments ({centerline, left_laneline, right_laneline,
  // confidence}, topology_lsls) and areas ({category, points, confidence}; optional).
  bool map_elements(const object& p, element segments_e, const std::string& at, FrameCenterlines& f) {
    f.has_map_elements = true;
    array segments;
    const std::string seg_at = at + "/predictions/lane_segment";
    if (segments_e.get_array().get(segments)) {
      problem("frames.results.schema", seg_at, "an array of lane segments");
      return false;
    }
    if (!within_count(segments.size(), seg_at, "lane segments")) return false;
    size_t i = 0;
    for (const element s : segments) {
      const std::string here = seg_at + "/" + std::to_string(i++);
      SegmentLines lines;
      std::optional<double> conf;
      if (!s.is_object()) {
        problem("frames.results.schema", here,
                "a lane segment {centerline, left_laneline, right_laneline, confidence}");
        return false;
      }
      if (!line(s, here, "centerline", &lines.centerline) || !line(s, here, "left_laneline", &lines.left) ||
          !line(s, here, "right_laneline", &lines.right) || !confidence(s, here, &conf))
        return false;
      f.segments.push_back(std::move(lines));
      f.segment_confidence.push_back(*conf);
    }
    element topology_e;
    if (p.at_key("topology_lsls").get(topology_e)) {
      problem(
          "frames.results.schema", at + "/predictions/topology_lsls",
          std::to_string(f.segments.size()) + " × " + std::to_string(f.segments.size()) + " probabilities in [0, 1]");
      return false;
    }
    if (!topology(topology_e, at + "/predictions/topology_lsls", f.segments.size(), f.topology_lsls)) return false;
    element areas_e;
    if (p.at_key("area").get(areas_e) != simdjson::SUCCESS) return true;
    array areas;
    if (areas_e.get_array().get(areas)) {
      problem("frames.results.schema", at + "/predictions/area", "an array of areas");
      return false;
    }
    if (!within_count(areas.size(), at + "/predictions/area", "areas")) return false;
    i = 0;
    for (const element a : areas) {
      const std::string here = at + "/predictions/area/" + std::to_string(i++);
      element category_e;
      int64_t category = 0;
      if (!a.is_object() || a.at_key("category").get(category_e) || category_e.get_int64().get(category) ||
          (category != 1 && category != 2)) {
        problem("frames.results.schema", here + "/category", "1 (pedestrian crossing) or 2 (road boundary)");
        return false;
      }
      AreaPoints area{static_cast<int>(category), {}};
      std::optional<double> conf;
      if (!line(a, here, "points", &area.points) || !confidence(a, here, &conf)) return false;
      f.areas.push_back(std::move(area));
      f.area_confidence.push_back(*conf);
    }
    return true;
  }

  bool confidence(element e, const std::string& at, std::optional<double>* conf) {
    element conf_e;
    if (!e.at_key("confidence").get(conf_e)) *conf = detail::number(conf_e);
    if (*conf && std::isfinite(**conf)) return true;
    problem("frames.results.finite", at + "/confidence", "a finite number");
    return false;
  }

  // A line `name` of `e`: 2 to max_points_per_centerline finite [x, y, z].
  bool line(element e, const std::string& at, const char* name, std::vector<Point3>* out) {
    element pts_e;
    array pts;
    if (e.at_key(name).get(pts_e) || pts_e.get_array().get(pts)) {
      problem("frames.results.schema", at + "/" + name, "[[x, y, z], …]");
      return false;
    }
    return curve(pts, at + "/" + name, out);
  }

  bool centerline(element lane, const std::string& at, FrameCenterlines& f, int64_t* points) {
    element pts_e, conf_e;
    array pts;
    if (!lane.is_object() || lane.at_key("points").get(pts_e) || pts_e.get_array().get(pts)) {
      problem("frames.results.schema", at, "{\"id\", \"points\": [[x, y, z], …], \"confidence\"}");
      return false;
    }
    std::optional<double> conf;
    if (!lane.at_key("confidence").get(conf_e)) conf = detail::number(conf_e);
    if (!conf || !std::isfinite(*conf)) {
      problem("frames.results.finite", at + "/confidence", "a finite number");
      return false;
    }
    std::vector<Point3> curve_points;
    if (!curve(pts, at + "/points", &curve_points)) return false;
    *points += static_cast<int64_t>(curve_points.size());
    f.lanes.push_back(std::move(curve_points));
    f.confidence.push_back(*conf);
    return true;
  }

  bool curve(const array& pts, const std::string& at, std::vector<Point3>* out) {
    if (pts.size() < 2 || static_cast<int64_t>(pts.size()) > limits_.max_points_per_centerline) {
      problem("frames.results.size", at,
              "2 to " + std::to_string(limits_.max_points_per_centerline) + " points (got " +
                  std::to_string(pts.size()) + ")");
      return false;
    }
    out->reserve(pts.size());
    size_t k = 0;
    for (const element q : pts) {
      array xyz;
      Point3 v{};
      bool ok = !q.get_array().get(xyz) && xyz.size() == 3;
      if (ok) {
        size_t c = 0;
        for (const element x : xyz) {
          const std::optional<double> n = detail::number(x);
          if (!n) {
            ok = false;
            break;
          }
          v[c++] = *n;
        }
      }
      if (!ok) {
        problem("frames.results.schema", at + "/" + std::to_string(k), "[x, y, z] numbers");
        return false;
      }
      for (const double x : v)
        if (!std::isfinite(x) || std::abs(x) > limits_.max_abs_coordinate_m) {
          problem("frames.results.finite", at + "/" + std::to_string(k),
                  "coordinates within ±" + std::to_string(static_cast<int64_t>(limits_.max_abs_coordinate_m)) + " m");
          return false;
        }
      out->push_back(v);
      ++k;
    }
    return true;
  }

  bool topology(element t, const std::string& at, size_t n, std::vector<double>& out) {
    const std::string shape = std::to_string(n) + " × " + std::to_string(n) + " probabilities in [0, 1]";
    array rows;
    if (t.get_array().get(rows) || rows.size() != n) {
      problem("frames.results.schema", at, shape);
      return false;
    }
    out.reserve(n * n);
    size_t i = 0;
    for (const element row_e : rows) {
      array row;
      if (row_e.get_array().get(row) || row.size() != n) {
        problem("frames.results.schema", at + "/" + std::to_string(i), shape);
        return false;
      }
      size_t j = 0;
      for (const element v : row) {
        const std::optional<double> p = detail::number(v);
        if (!p || !(*p >= 0.0 && *p <= 1.0)) {
          problem("frames.results.scores", at + "/" + std::to_string(i) + "/" + std::to_string(j),
                  "a probability in [0, 1]");
          return false;
        }
        out.push_back(*p);
        ++j;
      }
      ++i;
    }
    return true;
  }

  std::string label_;
  const FrameResultsLimits& limits_;
  Issues& issues_;
  bool ok_ = true;
};

}  // namespace

std::optional<FrameSet> read_frames_results(const std::filesystem::path& file, const FrameResultsLimits& limits,
                                            Issues& issues) {
  validate::SubmissionLimits reading;
  reading.max_file_bytes = limits.max_file_bytes;
  const std::optional<std::string> bytes = validate::read_submission_bytes(file, reading, issues);
  if (!bytes) return std::nullopt;
  const simdjson::padded_string text(*bytes);
  simdjson::dom::parser parser;
  element doc;
  if (!detail::parse_strict(parser, text, file.string(), limits.max_depth, limits.max_json_values, doc, issues))
    return std::nullopt;
  return ResultsReader(file.string(), limits, issues).read(doc);
}

}  // namespace nsg::metrics

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
    array lanes;
    element lanes_e;
    if (p.at_key("lane_centerline").get(lanes_e) || lanes_e.get_array().get(lanes)) {
      problem("frames.results.schema", at + "/predictions/lane_centerline", "an array of centerlines");
      return false;
    }
    if (static_cast<int64_t>(lanes.size()) > limits_.max_centerlines_per_frame) {
      problem("frames.results.size", at + "/predictions/lane_centerline",
              "at most " + std::to_string(limits_.max_centerlines_per_frame) + " centerlines (got " +
                  std::to_string(lanes.size()) + ")");
      return false;
    }
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
    if (!topology(topology_e, at + "/predictions/topology_lclc", f)) return false;
    const int64_t links = std::count_if(f.topology.begin(), f.topology.end(), [](double v) { return v > 0.5; });
    if (links > limits_.max_links_per_frame) {
      problem("frames.results.size", at + "/predictions/topology_lclc",
              "at most " + std::to_string(limits_.max_links_per_frame) + " links above 0.5 in a frame (got " +
                  std::to_string(links) + ")");
      return false;
    }
    return true;
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
    if (pts.size() < 2 || static_cast<int64_t>(pts.size()) > limits_.max_points_per_centerline) {
      problem("frames.results.size", at + "/points",
              "2 to " + std::to_string(limits_.max_points_per_centerline) + " points (got " +
                  std::to_string(pts.size()) + ")");
      return false;
    }
    std::vector<Point3> curve;
    curve.reserve(pts.size());
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
        problem("frames.results.schema", at + "/points/" + std::to_string(k), "[x, y, z] numbers");
        return false;
      }
      for (const double x : v)
        if (!std::isfinite(x) || std::abs(x) > limits_.max_abs_coordinate_m) {
          problem("frames.results.finite", at + "/points/" + std::to_string(k),
                  "coordinates within ±" + std::to_string(static_cast<int64_t>(limits_.max_abs_coordinate_m)) + " m");
          return false;
        }
      curve.push_back(v);
      ++k;
    }
    *points += static_cast<int64_t>(curve.size());
    f.lanes.push_back(std::move(curve));
    f.confidence.push_back(*conf);
    return true;
  }

  bool topology(element t, const std::string& at, FrameCenterlines& f) {
    const size_t n = f.lanes.size();
    const std::string shape = std::to_string(n) + " × " + std::to_string(n) + " probabilities in [0, 1]";
    array rows;
    if (t.get_array().get(rows) || rows.size() != n) {
      problem("frames.results.schema", at, shape);
      return false;
    }
    f.topology.reserve(n * n);
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
        f.topology.push_back(*p);
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

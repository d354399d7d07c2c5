// The inputs of frame scoring: the ground truth of an `nsgraph frames` export (through its
// manifest) and an OpenLane-V2 results document, a stranger's file checked before use.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

#include "nsg/core/error.h"
#include "nsg/core/files.h"
#include "nsg/core/json.h"
#include "nsg/core/sha256.h"
#include "nsg/metrics/frames.h"
#include "nsg/metrics/measure.h"
#include "nsg/validate/submission.h"

namespace nsg::metrics {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const json& need(const json& doc, const char* key, const std::string& file, const std::string& at,
                 const char* expected) {
  NSG_CHECK(doc.is_object() && doc.contains(key), ParseError, file, at + "/" + key, expected);
  return doc[key];
}

// One ground-truth annotation: lane_centerline[].points and topology_lclc, checked as our
// own writer writes them (a damaged export is named, not scored).
FrameCenterlines truth_of(const json& annotation, const std::string& file, const std::string& at) {
  FrameCenterlines out;
  const json& lanes = need(annotation, "lane_centerline", file, at, "the frame's centerlines");
  NSG_CHECK(lanes.is_array(), ParseError, file, at + "/lane_centerline", "an array of centerlines");
  for (size_t i = 0; i < lanes.size(); ++i) {
    const std::string where = at + "/lane_centerline/" + std::to_string(i);
    const json& points = need(lanes[i], "points", file, where, "its points");
    NSG_CHECK(points.is_array() && points.size() >= 2, ParseError, file, where + "/points", "at least 2 points");
    std::vector<Point3> curve;
    for (const json& p : points) {
      NSG_CHECK(p.is_array() && p.size() == 3 && p[0].is_number() && p[1].is_number() && p[2].is_number(), ParseError,
                file, where + "/points", "[x, y, z] numbers");
      curve.push_back({p[0].get<double>(), p[1].get<double>(), p[2].get<double>()});
    }
    out.lanes.push_back(std::move(curve));
  }
  const size_t n = out.lanes.size();
  const json& topo = need(annotation, "topology_lclc", file, at, "the lane-lane topology");
  NSG_CHECK(topo.is_array() && topo.size() == n, ParseError, file, at + "/topology_lclc",
            std::to_string(n) + " rows (one per centerline)");
  for (const json& row : topo) {
    NSG_CHECK(row.is_array() && row.size() == n, ParseError, file, at + "/topology_lclc",
              std::to_string(n) + " columns of 0 or 1");
    for (const json& v : row) {
      NSG_CHECK(v == 0 || v == 1, ParseError, file, at + "/topology_lclc", "0 or 1");
      out.topology.push_back(v.get<double>());
    }
  }
  return out;
}

// Results checks: each problem is an issue naming the value; `ok` goes false.
class ResultsReader {
 public:
  ResultsReader(std::string label, const FrameResultsLimits& limits, Issues& issues)
      : label_(std::move(label)), limits_(limits), issues_(issues) {}

  std::optional<FrameSet> read(const json& doc) {
    if (!doc.is_object() || !doc.contains("results") || !doc["results"].is_object()) {
      problem("frames.results.schema", "", "an object with \"results\": {sample token: {\"predictions\": …}}");
      return std::nullopt;
    }
    FrameSet out;
    for (const auto& [token, entry] : doc["results"].items()) {
      const std::string at = "/results/" + validate::json_pointer_token(token);
      FrameCenterlines f;
      if (frame(entry, at, f)) out.emplace_back(token, std::move(f));
    }
    if (!ok_) return std::nullopt;
    return out;
  }

 private:
  void problem(const char* check, const std::string& at, const std::string& expected) {
    issues_.error(check, label_ + ":" + at, "expected " + expected);
    ok_ = false;
  }

  bool frame(const json& entry, const std::string& at, FrameCenterlines& f) {
    if (!entry.is_object() || !entry.contains("predictions") || !entry["predictions"].is_object()) {
      problem("frames.results.schema", at, "{\"predictions\": {\"lane_centerline\": […], \"topology_lclc\": […]}}");
      return false;
    }
    const json& p = entry["predictions"];
    if (!p.contains("lane_centerline") || !p["lane_centerline"].is_array()) {
      problem("frames.results.schema", at + "/predictions/lane_centerline", "an array of centerlines");
      return false;
    }
    const json& lanes = p["lane_centerline"];
    if (static_cast<int64_t>(lanes.size()) > limits_.max_centerlines_per_frame) {
      problem("frames.results.size", at + "/predictions/lane_centerline",
              "at most " + std::to_string(limits_.max_centerlines_per_frame) + " centerlines (got " +
                  std::to_string(lanes.size()) + ")");
      return false;
    }
    int64_t points = 0;
    for (size_t i = 0; i < lanes.size(); ++i)
      if (!centerline(lanes[i], at + "/predictions/lane_centerline/" + std::to_string(i), f, &points)) return false;
    if (points > limits_.max_points_per_frame) {
      problem("frames.results.size", at + "/predictions/lane_centerline",
              "at most " + std::to_string(limits_.max_points_per_frame) + " points in a frame (got " +
                  std::to_string(points) + ")");
      return false;
    }
    if (!topology(p, at + "/predictions/topology_lclc", f)) return false;
    const int64_t links = std::count_if(f.topology.begin(), f.topology.end(), [](double v) { return v > 0.5; });
    if (links > limits_.max_links_per_frame) {
      problem("frames.results.size", at + "/predictions/topology_lclc",
              "at most " + std::to_string(limits_.max_links_per_frame) + " links above 0.5 in a frame (got " +
                  std::to_string(links) + ")");
      return false;
    }
    return true;
  }

  bool centerline(const json& lane, const std::string& at, FrameCenterlines& f, int64_t* points) {
    if (!lane.is_object() || !lane.contains("points") || !lane["points"].is_array()) {
      problem("frames.results.schema", at, "{\"id\", \"points\": [[x, y, z], …], \"confidence\"}");
      return false;
    }
    const json& conf = lane.contains("confidence") ? lane["confidence"] : json();
    if (!conf.is_number() || !std::isfinite(conf.get<double>())) {
      problem("frames.results.finite", at + "/confidence", "a finite number");
      return false;
    }
    const json& pts = lane["points"];
    if (pts.size() < 2 || static_cast<int64_t>(pts.size()) > limits_.max_points_per_centerline) {
      problem("frames.results.size", at + "/points",
              "2 to " + std::to_string(limits_.max_points_per_centerline) + " points (got " +
                  std::to_string(pts.size()) + ")");
      return false;
    }
    std::vector<Point3> curve;
    for (size_t k = 0; k < pts.size(); ++k) {
      const json& q = pts[k];
      if (!q.is_array() || q.size() != 3 || !q[0].is_number() || !q[1].is_number() || !q[2].is_number()) {
        problem("frames.results.schema", at + "/points/" + std::to_string(k), "[x, y, z] numbers");
        return false;
      }
      const Point3 v{q[0].get<double>(), q[1].get<double>(), q[2].get<double>()};
      for (const double c : v)
        if (!std::isfinite(c) || std::abs(c) > limits_.max_abs_coordinate_m) {
          problem("frames.results.finite", at + "/points/" + std::to_string(k),
                  "coordinates within ±" + std::to_string(static_cast<int64_t>(limits_.max_abs_coordinate_m)) + " m");
          return false;
        }
      curve.push_back(v);
    }
    *points += static_cast<int64_t>(curve.size());
    f.lanes.push_back(std::move(curve));
    f.confidence.push_back(conf.get<double>());
    return true;
  }

  bool topology(const json& p, const std::string& at, FrameCenterlines& f) {
    const size_t n = f.lanes.size();
    const std::string shape = std::to_string(n) + " × " + std::to_string(n) + " probabilities in [0, 1]";
    if (!p.contains("topology_lclc") || !p["topology_lclc"].is_array() || p["topology_lclc"].size() != n) {
      problem("frames.results.schema", at, shape);
      return false;
    }
    for (size_t i = 0; i < n; ++i) {
      const json& row = p["topology_lclc"][i];
      if (!row.is_array() || row.size() != n) {
        problem("frames.results.schema", at + "/" + std::to_string(i), shape);
        return false;
      }
      for (size_t j = 0; j < n; ++j) {
        const json& v = row[j];
        if (!v.is_number() || !(v.get<double>() >= 0.0 && v.get<double>() <= 1.0)) {
          problem("frames.results.scores", at + "/" + std::to_string(i) + "/" + std::to_string(j),
                  "a probability in [0, 1]");
          return false;
        }
        f.topology.push_back(v.get<double>());
      }
    }
    return true;
  }

  std::string label_;
  const FrameResultsLimits& limits_;
  Issues& issues_;
  bool ok_ = true;
};

}  // namespace

FrameSet read_frames_ground_truth(const fs::path& export_dir, const std::string& split, bool verify) {
  const fs::path manifest_path = export_dir / "manifest.json";
  NSG_CHECK(fs::exists(manifest_path), IoError, manifest_path.string(), "",
            "an nsgraph frames export (its manifest.json)");
  const json manifest = parse_json_strict(read_file(manifest_path), manifest_path.string());
  NSG_CHECK(manifest.value("kind", "") == "nsgraph-frames", ParseError, manifest_path.string(), "/kind",
            "\"nsgraph-frames\" (the manifest of an `nsgraph frames` export)");
  const json& files = need(manifest, "files", manifest_path.string(), "", "the export's files");
  NSG_CHECK(files.is_array(), ParseError, manifest_path.string(), "/files", "an array of files");
  FrameSet out;
  const std::string prefix = split + "/";
  for (size_t i = 0; i < files.size(); ++i) {
    const json& f = files[i];
    const std::string at = "/files/" + std::to_string(i);
    const json& path = need(f, "path", manifest_path.string(), at, "the file's path");
    NSG_CHECK(path.is_string(), ParseError, manifest_path.string(), at + "/path", "a relative path");
    const std::string rel = path.get<std::string>();
    if (rel.rfind(prefix, 0) != 0 || rel.find("/info/") == std::string::npos) continue;
    NSG_CHECK(rel.find("..") == std::string::npos && !rel.empty() && rel[0] != '/', ParseError, manifest_path.string(),
              at + "/path", "a path inside the export");
    const fs::path file = export_dir / rel;
    NSG_CHECK(fs::exists(file), DataError, file.string(), rel, "present, as " + manifest_path.string() + " lists it");
    const std::string text = read_file(file);
    NSG_CHECK(static_cast<int64_t>(text.size()) == f.value("bytes", int64_t{-1}), DataError, file.string(), rel,
              "the size " + manifest_path.string() + " records");
    if (verify)
      NSG_CHECK(sha256_hex(text) == f.value("sha256", ""), DataError, file.string(), rel,
                "the sha256 " + manifest_path.string() + " records");
    const json record = parse_json_strict(text, file.string());
    const json& token = need(record, "sample_token", file.string(), "", "the frame's sample token");
    NSG_CHECK(token.is_string(), ParseError, file.string(), "/sample_token", "a sample token");
    out.emplace_back(token.get<std::string>(), truth_of(need(record, "annotation", file.string(), "", "the annotation"),
                                                        file.string(), "/annotation"));
  }
  NSG_CHECK(!out.empty(), DataError, manifest_path.string(), split,
            "a split with frames (the manifest lists no record under " + prefix + ")");
  return out;
}

FrameSet read_frames_ground_truth_document(const fs::path& file) {
  const json doc = parse_json_strict(read_file(file), file.string());
  const json& frames = need(doc, "frames", file.string(), "", "{\"frames\": {key: annotation}}");
  NSG_CHECK(frames.is_object(), ParseError, file.string(), "/frames", "an object of frames");
  FrameSet out;
  for (const auto& [key, annotation] : frames.items())
    out.emplace_back(key, truth_of(annotation, file.string(), "/frames/" + validate::json_pointer_token(key)));
  return out;
}

std::optional<FrameSet> read_frames_results(const fs::path& file, const FrameResultsLimits& limits, Issues& issues) {
  validate::SubmissionLimits reading;
  reading.max_file_bytes = limits.max_file_bytes;
  reading.max_json_values = limits.max_json_values;
  reading.max_depth = limits.max_depth;
  const std::optional<json> doc = validate::read_submission(file, reading, issues);
  if (!doc) return std::nullopt;
  return ResultsReader(file.string(), limits, issues).read(*doc);
}

void check_frame_work(const FrameSet& truth, const FrameSet& predictions, const FrameResultsLimits& limits,
                      const std::string& results_label, Issues& issues) {
  std::map<std::string, int64_t> truth_points;
  for (const auto& [key, f] : truth) {
    int64_t n = 0;
    for (const auto& lane : f.lanes) n += static_cast<int64_t>(lane.size());
    truth_points[key] = n;
  }
  for (const auto& [key, f] : predictions) {
    const auto it = truth_points.find(key);
    if (it == truth_points.end()) continue;  // an extra frame is not measured
    // Its graph (rule 9) within the tile limits, as a tile's prediction would be.
    const Graph g = frame_graph(f, false);
    double length_px = 0.0;
    for (const auto& [a, b] : g.edges)
      length_px += std::hypot(g.nodes[static_cast<size_t>(a)].u - g.nodes[static_cast<size_t>(b)].u,
                              g.nodes[static_cast<size_t>(a)].v - g.nodes[static_cast<size_t>(b)].v);
    validate::check_tile_limits(static_cast<int64_t>(g.nodes.size()), static_cast<int64_t>(g.edges.size()), length_px,
                                validate::path_search_work(static_cast<int64_t>(g.nodes.size()), g.edges),
                                results_label + ":/results/" + validate::json_pointer_token(key),
                                validate::SubmissionLimits{}, issues);
    int64_t n = 0;
    for (const auto& lane : f.lanes) n += static_cast<int64_t>(lane.size());
    if (n > 0 && it->second > limits.max_point_pairs_per_frame / n)
      issues.error("frames.results.size", results_label + ":/results/" + validate::json_pointer_token(key),
                   "expected at most " + std::to_string(limits.max_point_pairs_per_frame) +
                       " ground-truth x predicted point pairs in a frame (got " + std::to_string(it->second) + " x " +
                       std::to_string(n) + ")");
  }
}

ScoredFrames score_frames_submission(const FramesScoreInput& input) {
  const FrameSet truth = fs::is_directory(input.ground_truth)
                             ? read_frames_ground_truth(input.ground_truth, input.split, input.verify)
                             : read_frames_ground_truth_document(input.ground_truth);
  ScoredFrames out;
  const std::optional<FrameSet> predictions = read_frames_results(input.results, input.limits, out.issues);
  if (!predictions) return out;
  check_frame_work(truth, *predictions, input.limits, input.results.string(), out.issues);
  if (!out.issues.empty()) return out;
  try {
    out.report = score_frames(truth, *predictions);
  } catch (const SearchWorkExceeded& e) {  // a prediction costlier than the tile limit allows
    out.issues.error("frames.results.size", input.results.string() + ":" + e.record(), e.expected());
    out.report.reset();
    return out;
  }
  out.report->split = fs::is_directory(input.ground_truth) ? input.split : "";
  return out;
}

}  // namespace nsg::metrics

// The inputs of frame scoring: the ground truth of an `nsgraph frames` export (its records
// through frames_documents.h's readers) or a ground-truth document (the golden set's), and an
// OpenLane-V2 results document, a stranger's file checked before use.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

#include "nsg/core/error.h"
#include "nsg/core/files.h"
#include "nsg/core/json.h"
#include "frames_json.h"
#include "nsg/metrics/frames.h"
#include "nsg/metrics/measure.h"
#include "nsg/validate/submission.h"

namespace nsg::metrics {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// A member of a ground-truth object, ParseError naming the file and pointer when absent.
simdjson::dom::element member(simdjson::dom::element e, const char* key, const std::string& file, const std::string& at,
                              const char* expected) {
  simdjson::dom::element out;
  NSG_CHECK(!e.at_key(key).get(out), ParseError, file, at + "/" + key, expected);
  return out;
}

// One ground-truth annotation: lane_centerline[].points and topology_lclc, checked as our
// own writer writes them (a damaged export is named, not scored).
std::vector<Point3> truth_points(simdjson::dom::element e, const std::string& file, const std::string& at) {
  simdjson::dom::array points;
  NSG_CHECK(!e.get_array().get(points) && points.size() >= 2, ParseError, file, at, "at least 2 points");
  std::vector<Point3> curve;
  for (const simdjson::dom::element p : points) {
    simdjson::dom::array xyz;
    NSG_CHECK(!p.get_array().get(xyz) && xyz.size() == 3, ParseError, file, at, "[x, y, z] numbers");
    Point3 v{};
    size_t c = 0;
    for (const simdjson::dom::element x : xyz) {
      const std::optional<double> n = detail::number(x);
      NSG_CHECK(n.has_value(), ParseError, file, at, "[x, y, z] numbers");
      v[c++] = *n;
    }
    curve.push_back(v);
  }
  return curve;
}

// An n × n matrix of 0 or 1, appended to `out` row by row.
void truth_topology(simdjson::dom::element annotation, const char* name, size_t n, const std::string& file,
                    const std::string& at, std::vector<double>& out) {
  simdjson::dom::array topo;
  NSG_CHECK(!member(annotation, name, file, at, "the topology").get_array().get(topo) && topo.size() == n, ParseError,
            file, at + "/" + name, std::to_string(n) + " rows (one per lane)");
  for (const simdjson::dom::element row_e : topo) {
    simdjson::dom::array row;
    NSG_CHECK(!row_e.get_array().get(row) && row.size() == n, ParseError, file, at + "/" + name,
              std::to_string(n) + " columns of 0 or 1");
    for (const simdjson::dom::element v : row) {
      const std::optional<double> x = detail::number(v);
      NSG_CHECK(x && (*x == 0.0 || *x == 1.0), ParseError, file, at + "/" + name, "0 or 1");
      out.push_back(*x);
    }
  }
}

// A golden document's lane segments and areas, as a record's (resampled as collect() does).
void map_elements_of(simdjson::dom::element annotation, const std::string& file, const std::string& at,
                     FrameCenterlines& out) {
  simdjson::dom::array segments, areas;
  NSG_CHECK(!member(annotation, "lane_segment", file, at, "the lane segments").get_array().get(segments), ParseError,
            file, at + "/lane_segment", "an array of lane segments");
  size_t i = 0;
  for (const simdjson::dom::element s : segments) {
    const std::string where = at + "/lane_segment/" + std::to_string(i++);
    const auto line = [&](const char* name) {
      return interpolate_like_collect(truth_points(member(s, name, file, where, name), file, where + "/" + name),
                                      kLaneSegmentLinePoints);
    };
    out.segments.push_back({line("centerline"), line("left_laneline"), line("right_laneline")});
  }
  truth_topology(annotation, "topology_lsls", out.segments.size(), file, at, out.topology_lsls);
  NSG_CHECK(!member(annotation, "area", file, at, "the areas").get_array().get(areas), ParseError, file, at + "/area",
            "an array of areas");
  i = 0;
  for (const simdjson::dom::element a : areas) {
    const std::string where = at + "/area/" + std::to_string(i++);
    int64_t category = 0;
    NSG_CHECK(
        !member(a, "category", file, where, "1 or 2").get_int64().get(category) && (category == 1 || category == 2),
        ParseError, file, where + "/category", "1 (pedestrian crossing) or 2 (road boundary)");
    out.areas.push_back(
        {static_cast<int>(category),
         interpolate_like_collect(truth_points(member(a, "points", file, where, "its points"), file, where + "/points"),
                                  kAreaPoints)});
  }
  out.has_map_elements = true;
}

FrameCenterlines truth_of(simdjson::dom::element annotation, const std::string& file, const std::string& at) {
  FrameCenterlines out;
  simdjson::dom::array lanes;
  NSG_CHECK(!member(annotation, "lane_centerline", file, at, "the frame's centerlines").get_array().get(lanes),
            ParseError, file, at + "/lane_centerline", "an array of centerlines");
  size_t i = 0;
  for (const simdjson::dom::element lane : lanes) {
    const std::string where = at + "/lane_centerline/" + std::to_string(i++);
    out.lanes.push_back(truth_points(member(lane, "points", file, where, "its points"), file, where + "/points"));
  }
  truth_topology(annotation, "topology_lclc", out.lanes.size(), file, at, out.topology);
  simdjson::dom::element segments;
  if (annotation.at_key("lane_segment").get(segments) == simdjson::SUCCESS) map_elements_of(annotation, file, at, out);
  return out;
}

// Parses one of the ground truth's files (our own, still refused by name when damaged).
simdjson::dom::element parse_truth(simdjson::dom::parser& parser, const std::string& text, const std::string& file) {
  simdjson::dom::element doc;
  NSG_CHECK(!parser.parse(text).get(doc), ParseError, file, "", "JSON (an nsgraph frames document)");
  return doc;
}

}  // namespace

FrameSet read_frames_ground_truth(const fs::path& export_dir, const std::string& split, bool verify,
                                  std::map<std::string, std::string>* token_by_identifier) {
  const FramesManifest manifest = read_frames_manifest(export_dir);
  FrameSet out;
  for_each_frame_record(manifest, split, verify, [&](const FrameRecord& record, const FramesListedFile&) {
    out.emplace_back(record.sample_token, record.truth());
    if (token_by_identifier) (*token_by_identifier)[record.identifier()] = record.sample_token;
  });
  NSG_CHECK(!out.empty(), DataError, manifest.file.string(), split,
            "a split with frames (the manifest lists no record under " + split + "/)");
  return out;
}

FrameSet read_frames_ground_truth_document(const fs::path& file) {
  simdjson::dom::parser parser;
  const simdjson::dom::element doc = parse_truth(parser, read_file(file), file.string());
  simdjson::dom::object frames;
  NSG_CHECK(!member(doc, "frames", file.string(), "", "{\"frames\": {key: annotation}}").get_object().get(frames),
            ParseError, file.string(), "/frames", "an object of frames");
  FrameSet out;
  for (const auto field : frames) {
    const std::string key(field.key);
    out.emplace_back(key, truth_of(field.value, file.string(), "/frames/" + validate::json_pointer_token(key)));
  }
  return out;
}

// Points of a frame's lane segments (three lines each) and areas: what DET_ls and DET_a
// compare pairwise.
int64_t map_element_points(const FrameCenterlines& f) {
  int64_t n = 0;
  for (const SegmentLines& s : f.segments)
    n += static_cast<int64_t>(s.centerline.size() + s.left.size() + s.right.size());
  for (const AreaPoints& a : f.areas) n += static_cast<int64_t>(a.points.size());
  return n;
}

void check_frame_work(const FrameSet& truth, const FrameSet& predictions, const FrameResultsLimits& limits,
                      const std::string& results_label, Issues& issues) {
  std::map<std::string, std::pair<int64_t, int64_t>> truth_points;  // centerlines, map elements
  for (const auto& [key, f] : truth) {
    int64_t n = 0;
    for (const auto& lane : f.lanes) n += static_cast<int64_t>(lane.size());
    truth_points[key] = {n, map_element_points(f)};
  }
  for (const auto& [key, f] : predictions) {
    const auto it = truth_points.find(key);
    if (it == truth_points.end()) continue;  // an extra frame is not measured
    const std::string at = results_label + ":/results/" + validate::json_pointer_token(key);
    // Its graph (rule 9) within the tile limits, as a tile's prediction would be.
    const Graph g = frame_graph(f, false);
    double length_px = 0.0;
    for (const auto& [a, b] : g.edges)
      length_px += std::hypot(g.nodes[static_cast<size_t>(a)].u - g.nodes[static_cast<size_t>(b)].u,
                              g.nodes[static_cast<size_t>(a)].v - g.nodes[static_cast<size_t>(b)].v);
    validate::check_tile_limits(static_cast<int64_t>(g.nodes.size()), static_cast<int64_t>(g.edges.size()), length_px,
                                validate::path_search_work(static_cast<int64_t>(g.nodes.size()), g.edges), at,
                                validate::SubmissionLimits{}, issues);
    int64_t n = 0;
    for (const auto& lane : f.lanes) n += static_cast<int64_t>(lane.size());
    const auto bound = [&](int64_t gt, int64_t pred) {
      if (pred > 0 && gt > limits.max_point_pairs_per_frame / pred)
        issues.error("frames.results.size", at,
                     "expected at most " + std::to_string(limits.max_point_pairs_per_frame) +
                         " ground-truth x predicted point pairs in a frame (got " + std::to_string(gt) + " x " +
                         std::to_string(pred) + ")");
    };
    bound(it->second.first, n);
    bound(it->second.second, map_element_points(f));
  }
}

void key_results_by_token(FrameSet& predictions, const std::map<std::string, std::string>& token_by_identifier,
                          const std::string& results_label, Issues& issues) {
  std::map<std::string, std::string> key_of_frame;  // the token → the key that named it first
  for (auto& [key, frame] : predictions) {
    const auto it = token_by_identifier.find(key);
    const std::string token = it == token_by_identifier.end() ? key : it->second;
    const auto [first, inserted] = key_of_frame.emplace(token, key);
    if (!inserted)
      issues.error("frames.results.duplicate", results_label + ":/results/" + validate::json_pointer_token(key),
                   "one prediction per frame (\"" + first->second + "\" already names the key frame " + token +
                       ", by sample token or as split/segment_id/timestamp)");
    key = token;
  }
}

ScoredFrames score_frames_submission(const FramesScoreInput& input) {
  NSG_CHECK(std::isfinite(input.max_seconds) && input.max_seconds >= 0, ConfigError, "", "--max-seconds",
            "0 (no limit) or a number of seconds");
  std::map<std::string, std::string> token_by_identifier;
  const FrameSet truth =
      fs::is_directory(input.ground_truth)
          ? read_frames_ground_truth(input.ground_truth, input.split, input.verify, &token_by_identifier)
          : read_frames_ground_truth_document(input.ground_truth);
  ScoredFrames out;
  std::optional<FrameSet> predictions = read_frames_results(input.results, input.limits, out.issues);
  if (!predictions) return out;
  key_results_by_token(*predictions, token_by_identifier, input.results.string(), out.issues);
  if (!out.issues.empty()) return out;
  check_frame_work(truth, *predictions, input.limits, input.results.string(), out.issues);
  if (!out.issues.empty()) return out;
  try {
    out.report = score_frames(truth, *predictions, input.graph_metrics, input.max_seconds);
  } catch (const SearchWorkExceeded& e) {  // a prediction costlier than the tile limit allows
    out.issues.error("frames.results.size", input.results.string() + ":" + e.record(), e.expected());
    out.report.reset();
    return out;
  }
  out.report->split = fs::is_directory(input.ground_truth) ? input.split : "";
  return out;
}

}  // namespace nsg::metrics

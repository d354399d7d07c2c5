#include "nsg/graph/lane_graph.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>
#include <unordered_set>

#include "nsg/core/error.h"
#include "nsg/core/options.h"
#include "nsg/core/strings.h"

namespace nsg::graph {
namespace {

double distance(const Node& a, const Node& b) { return std::hypot(b.x_m - a.x_m, b.y_m - a.y_m); }

// Union–find over node indices; the representative is the smallest index so the merged
// graph does not depend on the order in which joins are found.
class NodeUnion {
 public:
  explicit NodeUnion(size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0); }
  int32_t find(int32_t i) {
    while (parent_[i] != i) i = parent_[i] = parent_[parent_[i]];
    return i;
  }
  void join(int32_t a, int32_t b) {
    a = find(a);
    b = find(b);
    if (a == b) return;
    if (b < a) std::swap(a, b);
    parent_[b] = a;
  }

 private:
  std::vector<int32_t> parent_;
};

bool contains(const std::vector<std::string>& list, const std::string& token) {
  return std::find(list.begin(), list.end(), token) != list.end();
}

// Map defects found while building; reported as warnings, or thrown with --strict. Facts
// the real maps are full of and that break nothing (disconnected lanes: devkit README)
// are infos, which --strict lets through.
struct DefectLog {
  std::vector<Issue> found;
  void add(const std::string& check, const std::string& token, const std::string& message,
           Severity severity = Severity::kWarning) {
    found.push_back({severity, "graph." + check, token, message});
  }
};

void check_connectivity(const std::vector<LaneSource>& sources, const std::unordered_map<std::string, int32_t>& index,
                        DefectLog* log) {
  for (const LaneSource& a : sources) {
    if (!a.has_connectivity) {
      log->add("missing_connectivity", a.token, "token has no entry in `connectivity`");
      continue;
    }
    for (const std::string& b : a.outgoing) {
      auto it = index.find(b);
      if (it == index.end()) {
        log->add("dangling_connectivity", a.token,
                 "outgoing names " + b + ", which is neither a lane nor a lane connector");
      } else if (sources[it->second].has_connectivity && !contains(sources[it->second].incoming, a.token)) {
        log->add("unmirrored_connectivity", a.token,
                 "outgoing names " + b + " but its incoming list does not name " + a.token);
      }
    }
    for (const std::string& c : a.incoming) {
      auto it = index.find(c);
      if (it == index.end()) {
        log->add("dangling_connectivity", a.token,
                 "incoming names " + c + ", which is neither a lane nor a lane connector");
      } else if (sources[it->second].has_connectivity && !contains(sources[it->second].outgoing, a.token)) {
        log->add("unmirrored_connectivity", a.token,
                 "incoming names " + c + " but its outgoing list does not name " + a.token);
      }
    }
  }
}

// A join moves a lane's first node onto its predecessor's last one, up to the join
// tolerance away (real maps: a few mm, docs/nuscenes-input.md), which can stretch the first edge past
// max_spacing; such an edge gets evenly spaced nodes inserted. Float noise of the
// resampling (1e-13 m) is not worth a node.
void split_long_edges(Lane& lane, std::vector<Node>& nodes, double max_spacing_m) {
  constexpr double kSlackM = 1e-9;
  std::vector<int32_t> out;
  out.reserve(lane.nodes.size());
  for (size_t k = 0; k < lane.nodes.size(); ++k) {
    if (k > 0) {
      const Node a = nodes[lane.nodes[k - 1]], b = nodes[lane.nodes[k]];
      const double d = distance(a, b);
      if (d > max_spacing_m + kSlackM) {
        const size_t parts = static_cast<size_t>(std::ceil(d / max_spacing_m));
        for (size_t i = 1; i < parts; ++i) {
          const double t = static_cast<double>(i) / static_cast<double>(parts);
          out.push_back(static_cast<int32_t>(nodes.size()));
          nodes.push_back({a.x_m + t * (b.x_m - a.x_m), a.y_m + t * (b.y_m - a.y_m)});
        }
      }
    }
    out.push_back(lane.nodes[k]);
  }
  lane.nodes = std::move(out);
}

}  // namespace

const options::Table<LaneGraphOptions>& lane_graph_option_table() {
  static const options::Table<LaneGraphOptions> table = [] {
    options::Table<LaneGraphOptions> t;
    t.number("graph.max_spacing_m", &LaneGraphOptions::max_spacing_m)
        .unit("m")
        .range(options::between(0.1, 100))
        .help(
            "Longest distance between consecutive nodes (lanes are resampled evenly to it; 0.1 m = half a pixel at "
            "the default resolution at least: the graph's size grows with its inverse)");
    t.number("graph.source_resolution_m", &LaneGraphOptions::source_resolution_m)
        .unit("m")
        .range(options::above(0))
        .help("Step of the devkit's arcline discretization before resampling");
    t.number("graph.join_tolerance_m", &LaneGraphOptions::join_tolerance_m)
        .unit("m")
        .range(options::at_least(0))
        .help("Lane ends closer than this become one node");
    t.boolean("graph.strict", &LaneGraphOptions::strict).help("Map defects are errors instead of reported issues");
    return t;
  }();
  return table;
}

void LaneGraphOptions::validate() const { lane_graph_option_table().check(*this); }

double LaneGraph::edge_length_m(const Edge& e) const { return distance(nodes[e.source], nodes[e.target]); }

double LaneGraph::max_edge_length_m() const {
  double longest = 0.0;
  for (const Edge& e : edges) longest = std::max(longest, edge_length_m(e));
  return longest;
}

int32_t LaneGraph::find_lane(const std::string& token) const {
  for (size_t i = 0; i < lanes.size(); ++i)
    if (lanes[i].token == token) return static_cast<int32_t>(i);
  return -1;
}

void throw_if_defects(const std::vector<Issue>& found, const std::string& map_label) {
  const auto defect = [](const Issue& i) { return i.severity != Severity::kInfo; };
  const auto first = std::find_if(found.begin(), found.end(), defect);
  if (first == found.end()) return;
  const auto count = std::count_if(found.begin(), found.end(), defect);
  throw DataError(
      map_label, first->subject,
      first->check + ": " + first->message + " (--strict; " + std::to_string(count) + " map defect(s) in all)");
}

std::vector<Node> joined_centerline(const std::vector<geometry::ArclinePath>& paths, double resolution_m) {
  std::vector<Node> line;
  for (size_t p = 0; p < paths.size(); ++p) {
    std::vector<geometry::Pose2> poses = geometry::discretize_arcline(paths[p], resolution_m);
    // The last pose of a path repeats the next path's start pose (the devkit keeps both);
    // keep the stored start pose of the next path.
    if (p + 1 < paths.size() && !poses.empty()) poses.pop_back();
    for (const geometry::Pose2& pose : poses) line.push_back({pose.x, pose.y});
  }
  return line;
}

std::vector<Node> resample_polyline(const std::vector<Node>& polyline, double max_spacing_m) {
  if (polyline.empty()) return {};
  std::vector<double> cumulative(polyline.size(), 0.0);
  for (size_t i = 1; i < polyline.size(); ++i)
    cumulative[i] = cumulative[i - 1] + distance(polyline[i - 1], polyline[i]);
  const double length = cumulative.back();
  const size_t n = std::max<size_t>(static_cast<size_t>(std::ceil(length / max_spacing_m)) + 1, 2);
  std::vector<Node> out;
  out.reserve(n);
  out.push_back(polyline.front());
  size_t seg = 1;
  for (size_t k = 1; k + 1 < n; ++k) {
    const double s = length * static_cast<double>(k) / static_cast<double>(n - 1);
    while (seg + 1 < polyline.size() && cumulative[seg] < s) ++seg;
    const double seg_len = cumulative[seg] - cumulative[seg - 1];
    const double t = seg_len > 0.0 ? (s - cumulative[seg - 1]) / seg_len : 0.0;
    const Node& a = polyline[seg - 1];
    const Node& b = polyline[seg];
    out.push_back({a.x_m + t * (b.x_m - a.x_m), a.y_m + t * (b.y_m - a.y_m)});
  }
  out.push_back(polyline.back());
  return out;
}

namespace {

using TokenIndex = std::unordered_map<std::string, int32_t>;

// Each lane's and connector's position in `sources` by token; a repeated token is a defect
// (the first keeps the token).
TokenIndex token_index(const std::vector<LaneSource>& sources, DefectLog& log) {
  TokenIndex index;
  for (size_t i = 0; i < sources.size(); ++i) {
    if (!index.emplace(sources[i].token, static_cast<int32_t>(i)).second)
      log.add("duplicate_token", sources[i].token, "token appears twice among lanes and connectors");
  }
  return index;
}

// 1. Each lane on its own: discretize, join, resample; the nodes of every lane in order.
LaneGraph separate_lanes(const std::vector<LaneSource>& sources, const LaneGraphOptions& options, DefectLog& log) {
  LaneGraph raw;
  raw.lanes.resize(sources.size());
  for (size_t i = 0; i < sources.size(); ++i) {
    const LaneSource& src = sources[i];
    Lane& lane = raw.lanes[i];
    lane.token = src.token;
    lane.is_connector = src.is_connector;
    if (src.paths.empty()) {
      log.add("no_arcline_path", src.token, "lane has no arcline_path_3 entry; left out of the graph");
      continue;
    }
    const std::vector<Node> line = joined_centerline(src.paths, options.source_resolution_m);
    for (size_t k = 1; k < line.size(); ++k) lane.length_m += distance(line[k - 1], line[k]);
    for (const Node& node : resample_polyline(line, options.max_spacing_m)) {
      lane.nodes.push_back(static_cast<int32_t>(raw.nodes.size()));
      raw.nodes.push_back(node);
    }
  }
  return raw;
}

// 2. Join ends across connectivity: a lane's last node and each outgoing lane's first one
// within the tolerance become one; their lanes are successors. Lanes that join none are
// reported.
NodeUnion join_ends(const std::vector<LaneSource>& sources, const TokenIndex& index, const LaneGraphOptions& options,
                    LaneGraph& raw, DefectLog& log) {
  NodeUnion joins(raw.nodes.size());
  std::vector<bool> connected(sources.size(), false);
  for (size_t a = 0; a < sources.size(); ++a) {
    for (const std::string& token : sources[a].outgoing) {
      auto it = index.find(token);
      if (it == index.end()) continue;
      const int32_t b = it->second;
      Lane& from = raw.lanes[a];
      const Lane& to = raw.lanes[b];
      if (from.nodes.empty() || to.nodes.empty()) continue;
      const double gap = distance(raw.nodes[from.nodes.back()], raw.nodes[to.nodes.front()]);
      if (gap > options.join_tolerance_m) {
        log.add("ends_apart", sources[a].token,
                "end is " + format_double(gap) + " m from the start of outgoing " + token + " (tolerance " +
                    format_double(options.join_tolerance_m) + " m); not joined");
        continue;
      }
      joins.join(from.nodes.back(), to.nodes.front());
      from.successors.push_back(b);
      connected[a] = connected[b] = true;
    }
  }
  for (size_t i = 0; i < sources.size(); ++i) {
    if (!connected[i] && !raw.lanes[i].nodes.empty())
      log.add("isolated_lane", sources[i].token, "lane joins no other lane (normal in real maps)", Severity::kInfo);
  }
  return joins;
}

// 3. Compact: representatives keep their own position; ids in order of first use. Then
// each lane's edges, long ones split.
LaneGraph compact(LaneGraph& raw, NodeUnion& joins, double max_spacing_m) {
  LaneGraph graph;
  graph.lanes = std::move(raw.lanes);
  std::vector<int32_t> new_id(raw.nodes.size(), -1);
  for (size_t i = 0; i < raw.nodes.size(); ++i) {
    const int32_t rep = joins.find(static_cast<int32_t>(i));
    if (new_id[rep] < 0) {
      new_id[rep] = static_cast<int32_t>(graph.nodes.size());
      graph.nodes.push_back(raw.nodes[rep]);
    }
    new_id[i] = new_id[rep];
  }
  for (size_t l = 0; l < graph.lanes.size(); ++l) {
    Lane& lane = graph.lanes[l];
    for (int32_t& n : lane.nodes) n = new_id[n];
    split_long_edges(lane, graph.nodes, max_spacing_m);
    for (size_t k = 1; k < lane.nodes.size(); ++k) {
      if (lane.nodes[k - 1] == lane.nodes[k]) continue;  // a zero-length lane joined to itself
      graph.edges.push_back({lane.nodes[k - 1], lane.nodes[k], static_cast<int32_t>(l)});
    }
  }
  return graph;
}

}  // namespace

LaneGraph build_lane_graph(const std::vector<LaneSource>& sources, const LaneGraphOptions& options, Issues* issues,
                           const std::string& map_label) {
  // `options` were checked where they were read (the config reader, or validate()).
  DefectLog log;
  const TokenIndex index = token_index(sources, log);
  check_connectivity(sources, index, &log);
  LaneGraph raw = separate_lanes(sources, options, log);
  NodeUnion joins = join_ends(sources, index, options, raw, log);
  LaneGraph graph = compact(raw, joins, options.max_spacing_m);
  for (const Issue& issue : log.found) {
    if (issues) issues->add(issue.severity, issue.check, issue.subject, issue.message);
  }
  if (options.strict) throw_if_defects(log.found, map_label);
  return graph;
}

}  // namespace nsg::graph

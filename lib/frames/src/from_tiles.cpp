// Tile predictions → per-frame results: stitch, cut, chain, link.
#include "nsg/frames/from_tiles.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>

#include "nsg/frames/frame_lanes.h"
#include "nsg/metrics/frames_documents.h"

namespace nsg::frames {
namespace {

namespace fs = std::filesystem;
using nlohmann::ordered_json;

double rounded_m(double v) { return std::round(v * 1e4) / 1e4; }  // as the records' coordinates

geometry::Rigid3 rigid_of(const metrics::FrameTransform& t) {
  geometry::Rigid3 out;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out.rotation(r, c) = t.rotation[static_cast<size_t>(r)][static_cast<size_t>(c)];
    out.translation(r) = t.translation[static_cast<size_t>(r)];
  }
  return out;
}

// One frame's kept edges between stitched nodes (map metres).
struct FrameGraph {
  std::vector<Eigen::Vector2d> nodes;
  std::vector<std::array<int32_t, 2>> edges;
  std::vector<double> scores;
};

Eigen::Vector2d map_point(const TilePrediction& t, const metrics::Point& p, double res) {
  return {t.bounds_m[0] + (p.u + 0.5) * res, t.bounds_m[3] - (p.v + 0.5) * res};
}

bool inside(const std::array<double, 4>& b, const Eigen::Vector2d& p) {
  return p.x() >= b[0] && p.x() <= b[2] && p.y() >= b[1] && p.y() <= b[3];
}

// Tiles meeting the window's bounding box; each edge kept by the tile nearest its midpoint.
FrameGraph stitch(const std::vector<const TilePrediction*>& tiles, double res, double join_m) {
  std::vector<Eigen::Vector2d> centres;
  for (const TilePrediction* t : tiles)
    centres.emplace_back((t->bounds_m[0] + t->bounds_m[2]) / 2, (t->bounds_m[1] + t->bounds_m[3]) / 2);
  FrameGraph g;
  std::vector<int32_t> tile_of_node;
  for (size_t k = 0; k < tiles.size(); ++k) {
    const TilePrediction& t = *tiles[k];
    std::vector<int32_t> id(t.graph.nodes.size(), -1);
    for (size_t e = 0; e < t.graph.edges.size(); ++e) {
      const auto [a, b] = t.graph.edges[e];
      const Eigen::Vector2d pa = map_point(t, t.graph.nodes[static_cast<size_t>(a)], res);
      const Eigen::Vector2d pb = map_point(t, t.graph.nodes[static_cast<size_t>(b)], res);
      const Eigen::Vector2d mid = (pa + pb) / 2;
      if (!inside(t.bounds_m, mid)) continue;
      size_t owner = k;
      for (size_t o = 0; o < tiles.size(); ++o)
        if (inside(tiles[o]->bounds_m, mid) && (mid - centres[o]).norm() < (mid - centres[owner]).norm()) owner = o;
      if (owner != k) continue;
      for (const auto& [node, p] : {std::pair{a, pa}, std::pair{b, pb}})
        if (id[static_cast<size_t>(node)] < 0) {
          id[static_cast<size_t>(node)] = static_cast<int32_t>(g.nodes.size());
          g.nodes.push_back(p);
          tile_of_node.push_back(static_cast<int32_t>(k));
        }
      g.edges.push_back({id[static_cast<size_t>(a)], id[static_cast<size_t>(b)]});
      g.scores.push_back(e < t.graph.edge_scores.size() ? t.graph.edge_scores[e] : 1.0);
    }
  }
  // Lane ends of different tiles within join_m become one node (nearest first, each once).
  std::vector<int32_t> degree(g.nodes.size(), 0);
  for (const auto& [a, b] : g.edges) ++degree[static_cast<size_t>(a)], ++degree[static_cast<size_t>(b)];
  std::vector<int32_t> merged(g.nodes.size());
  std::iota(merged.begin(), merged.end(), 0);
  std::vector<uint8_t> used(g.nodes.size(), 0);
  for (size_t i = 0; i < g.nodes.size(); ++i) {
    if (degree[i] != 1 || used[i]) continue;
    int32_t best = -1;
    double best_d = join_m;
    for (size_t j = i + 1; j < g.nodes.size(); ++j)
      if (degree[j] == 1 && !used[j] && tile_of_node[j] != tile_of_node[i] &&
          (g.nodes[j] - g.nodes[i]).norm() <= best_d) {
        best = static_cast<int32_t>(j);
        best_d = (g.nodes[j] - g.nodes[i]).norm();
      }
    if (best < 0) continue;
    used[i] = used[static_cast<size_t>(best)] = 1;
    merged[static_cast<size_t>(best)] = static_cast<int32_t>(i);
  }
  FrameGraph out;
  out.nodes = g.nodes;  // merged nodes keep the first one's position; the other is unused
  for (size_t e = 0; e < g.edges.size(); ++e) {
    const int32_t a = merged[static_cast<size_t>(g.edges[e][0])], b = merged[static_cast<size_t>(g.edges[e][1])];
    if (a == b) continue;
    out.edges.push_back({a, b});
    out.scores.push_back(g.scores[e]);
  }
  return out;
}

struct Chain {
  std::vector<int32_t> nodes;
  double score = 0.0;
};

// Maximal paths whose inner nodes have one edge in and one out; cycles start at their
// lowest edge.
std::vector<Chain> chains_of(const FrameGraph& g) {
  const size_t n = g.nodes.size();
  std::vector<int32_t> in(n, 0), out(n, 0);
  std::vector<std::vector<int32_t>> next(n);  // edge indices out of each node
  for (size_t e = 0; e < g.edges.size(); ++e) {
    ++out[static_cast<size_t>(g.edges[e][0])];
    ++in[static_cast<size_t>(g.edges[e][1])];
    next[static_cast<size_t>(g.edges[e][0])].push_back(static_cast<int32_t>(e));
  }
  const auto inner = [&](int32_t v) { return in[static_cast<size_t>(v)] == 1 && out[static_cast<size_t>(v)] == 1; };
  std::vector<uint8_t> done(g.edges.size(), 0);
  std::vector<Chain> chains;
  const auto follow = [&](size_t e) {
    Chain c;
    c.nodes.push_back(g.edges[e][0]);
    double sum = 0.0;
    size_t count = 0;
    while (true) {
      done[e] = 1;
      sum += g.scores[e];
      ++count;
      const int32_t v = g.edges[e][1];
      c.nodes.push_back(v);
      if (!inner(v)) break;
      const int32_t f = next[static_cast<size_t>(v)].front();
      if (done[static_cast<size_t>(f)]) break;  // closed a cycle
      e = static_cast<size_t>(f);
    }
    c.score = sum / static_cast<double>(count);
    chains.push_back(std::move(c));
  };
  for (size_t e = 0; e < g.edges.size(); ++e)
    if (!done[e] && !inner(g.edges[e][0])) follow(e);
  for (size_t e = 0; e < g.edges.size(); ++e)
    if (!done[e]) follow(e);
  return chains;
}

ordered_json frame_results(const FrameGraph& g, const geometry::Rigid3& global_from_ego, const ExportFrames& ex) {
  const geometry::Rigid3 ego_from_global = global_from_ego.inverse();
  struct Piece {
    FrameCenterline c;
    int32_t start_node, end_node;
    double score;
  };
  std::vector<Piece> pieces;
  const std::vector<Chain> chains = chains_of(g);
  for (size_t k = 0; k < chains.size(); ++k) {
    std::vector<Eigen::Vector3d> ego;
    for (const int32_t v : chains[k].nodes) {
      const Eigen::Vector2d& p = g.nodes[static_cast<size_t>(v)];
      ego.push_back(ego_from_global.apply(Eigen::Vector3d(p.x(), p.y(), 0.0)));
    }
    for (FrameCenterline& c : clip_chain(ego, ex.window, static_cast<int32_t>(k), "", false)) {
      c.points = resample_by_count(c.points_2m, ex.centerline_points);
      pieces.push_back({std::move(c), chains[k].nodes.front(), chains[k].nodes.back(), chains[k].score});
    }
  }
  ordered_json lanes = ordered_json::array();
  for (size_t i = 0; i < pieces.size(); ++i) {
    ordered_json points = ordered_json::array();
    for (const Eigen::Vector3d& p : pieces[i].c.points)
      points.push_back({rounded_m(p.x()), rounded_m(p.y()), rounded_m(p.z())});
    lanes.push_back({{"id", i}, {"points", points}, {"confidence", pieces[i].score}});
  }
  ordered_json topology = ordered_json::array();
  for (const Piece& a : pieces) {
    ordered_json row = ordered_json::array();
    for (const Piece& b : pieces)
      row.push_back(a.c.ends_at_lane_end && b.c.starts_at_lane_start && a.end_node == b.start_node ? 1.0 : 0.0);
    topology.push_back(row);
  }
  return {{"predictions",
           {{"lane_centerline", lanes}, {"traffic_element", ordered_json::array()}, {"topology_lclc", topology}}}};
}

}  // namespace

ExportFrames read_export_frames(const fs::path& export_dir, const std::string& split) {
  // The one reader of the export's documents (metrics/frames_documents.h): every field used
  // here is present, typed and in range, or the file is named with its JSON pointer.
  const metrics::FramesManifest manifest = metrics::read_frames_manifest(export_dir);
  ExportFrames out;
  out.window = {manifest.window.x_min_m, manifest.window.x_max_m, manifest.window.y_min_m, manifest.window.y_max_m};
  out.centerline_points = manifest.centerline_points;
  out.dataset_manifest_sha256 = manifest.dataset_manifest_sha256;
  metrics::for_each_frame_record(manifest, split, /*verify=*/true,
                                 [&](const metrics::FrameRecord& r, const metrics::FramesListedFile&) {
                                   out.frames.push_back({r.sample_token, r.meta_data.location, rigid_of(r.pose)});
                                 });
  return out;
}

nlohmann::ordered_json tiles_to_frame_results(const std::vector<TilePrediction>& tiles, const ExportFrames& ex,
                                              double resolution_m, const std::string& method, double join_m) {
  ordered_json results = ordered_json::object();
  for (const FramePose& f : ex.frames) {
    double x0 = std::numeric_limits<double>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
    for (const Eigen::Vector2d& c : window_corners_global(f.global_from_ego, ex.window)) {
      x0 = std::min(x0, c.x()), y0 = std::min(y0, c.y()), x1 = std::max(x1, c.x()), y1 = std::max(y1, c.y());
    }
    std::vector<const TilePrediction*> near;
    for (const TilePrediction& t : tiles)
      if (t.location == f.location && t.bounds_m[0] <= x1 && t.bounds_m[2] >= x0 && t.bounds_m[1] <= y1 &&
          t.bounds_m[3] >= y0)
        near.push_back(&t);
    results[f.token] = frame_results(stitch(near, resolution_m, join_m), f.global_from_ego, ex);
  }
  return {{"method", method}, {"results", results}};
}

}  // namespace nsg::frames

// The skeleton chain (skeleton.h): a binary mask thinned, traced into branches between
// ends and junctions, pruned and sampled into anchors. Moved from the reference model's b1
// unchanged, so its graphs stay byte-identical.
#include "nsg/skeleton/skeleton.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>
#include <opencv2/ximgproc.hpp>

#include "nsg/core/error.h"

namespace nsg::skeleton {
namespace {

// The skeleton as a pixel graph: 4-neighbours always connect; a diagonal neighbour only
// when no 4-neighbour path of two steps joins them (so staircases are simple chains).
struct PixelGraph {
  std::vector<cv::Point> pixels;
  std::vector<std::vector<int>> adjacent;
};

PixelGraph pixel_graph(const cv::Mat& skeleton) {
  PixelGraph g;
  cv::Mat id(skeleton.size(), CV_32S, cv::Scalar(-1));
  for (int v = 0; v < skeleton.rows; ++v) {
    for (int u = 0; u < skeleton.cols; ++u) {
      if (!skeleton.at<uint8_t>(v, u)) continue;
      id.at<int>(v, u) = static_cast<int>(g.pixels.size());
      g.pixels.push_back({u, v});
    }
  }
  auto on = [&](int u, int v) {
    return u >= 0 && v >= 0 && u < skeleton.cols && v < skeleton.rows && skeleton.at<uint8_t>(v, u) != 0;
  };
  g.adjacent.resize(g.pixels.size());
  static const int kRing[8][2] = {{0, -1}, {1, -1}, {1, 0}, {1, 1}, {0, 1}, {-1, 1}, {-1, 0}, {-1, -1}};
  for (size_t i = 0; i < g.pixels.size(); ++i) {
    const cv::Point p = g.pixels[i];
    for (const auto& d : kRing) {
      const int u = p.x + d[0], v = p.y + d[1];
      if (!on(u, v)) continue;
      const bool diagonal = d[0] != 0 && d[1] != 0;
      if (diagonal && (on(p.x + d[0], p.y) || on(p.x, p.y + d[1]))) continue;
      g.adjacent[i].push_back(id.at<int>(v, u));
    }
  }
  return g;
}

double polyline_length(const std::vector<cv::Point2d>& pts) {
  double len = 0.0;
  for (size_t k = 1; k < pts.size(); ++k) len += cv::norm(pts[k] - pts[k - 1]);
  return len;
}

}  // namespace

double sample_bilinear(const cv::Mat& map, double u, double v) {
  if (!(u >= 0.0 && v >= 0.0 && u <= map.cols - 1 && v <= map.rows - 1)) return 0.0;
  const int u0 = std::min(static_cast<int>(u), map.cols - 2), v0 = std::min(static_cast<int>(v), map.rows - 2);
  const double fu = u - u0, fv = v - v0;
  auto at = [&](int vv, int uu) { return static_cast<double>(map.at<float>(vv, uu)); };
  return (1 - fv) * ((1 - fu) * at(v0, u0) + fu * at(v0, u0 + 1)) +
         fv * ((1 - fu) * at(v0 + 1, u0) + fu * at(v0 + 1, u0 + 1));
}

double segment_score(const cv::Mat& likelihood, const std::array<double, 2>& a_uv, const std::array<double, 2>& b_uv) {
  const double du = b_uv[0] - a_uv[0], dv = b_uv[1] - a_uv[1];
  const int samples = std::max(2, static_cast<int>(std::ceil(std::hypot(du, dv))) + 1);
  double sum = 0.0;
  for (int s = 0; s < samples; ++s) {
    const double t = static_cast<double>(s) / (samples - 1);
    sum += sample_bilinear(likelihood, a_uv[0] + t * du, a_uv[1] + t * dv);
  }
  return sum / samples;
}

bool orient_a_to_b(const std::array<double, 2>& a_uv, const std::array<double, 2>& b_uv,
                   const std::array<double, 2>& mean_dir_a, const std::array<double, 2>& mean_dir_b) {
  const double du = b_uv[0] - a_uv[0], dv = b_uv[1] - a_uv[1];
  const double mu = mean_dir_a[0] + mean_dir_b[0], mv = mean_dir_a[1] + mean_dir_b[1];
  // dot(a→b, m) vs dot(b→a, m) = −dot(a→b, m): a→b wins unless its dot is negative.
  return du * mu + dv * mv >= 0.0;
}

cv::Mat drop_small_components(const cv::Mat& mask, int min_px) {
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
  cv::Mat out = cv::Mat::zeros(mask.size(), CV_8U);
  for (int v = 0; v < mask.rows; ++v) {
    for (int u = 0; u < mask.cols; ++u) {
      const int l = labels.at<int>(v, u);
      if (l > 0 && l < n && stats.at<int>(l, cv::CC_STAT_AREA) >= min_px) out.at<uint8_t>(v, u) = 255;
    }
  }
  return out;
}

cv::Mat thin(const cv::Mat& mask) {
  cv::Mat binary = (mask != 0), out;
  cv::ximgproc::thinning(binary, out, cv::ximgproc::THINNING_ZHANGSUEN);
  return out;
}

namespace {

// Vertices of the skeleton: every end (degree 1) alone; touching junction pixels (degree ≥ 3)
// together, at their mean. Appends them to out.vertices; returns each pixel's vertex or -1.
std::vector<int> group_vertices(const PixelGraph& g, const std::vector<int>& degree, SkeletonGraph& out) {
  const size_t n = g.pixels.size();
  std::vector<int> vertex_of(n, -1);
  for (size_t i = 0; i < n; ++i) {
    if (degree[i] == 2 || degree[i] == 0 || vertex_of[i] >= 0) continue;
    const int vid = static_cast<int>(out.vertices.size());
    std::vector<size_t> members{i}, stack{i};
    vertex_of[i] = vid;
    while (!stack.empty() && degree[i] >= 3) {
      const size_t p = stack.back();
      stack.pop_back();
      for (int q : g.adjacent[p]) {
        if (degree[q] >= 3 && vertex_of[q] < 0) {
          vertex_of[q] = vid;
          members.push_back(q);
          stack.push_back(q);
        }
      }
    }
    cv::Point2d c(0, 0);
    for (size_t m : members) c += cv::Point2d(g.pixels[m]);
    out.vertices.push_back(c / static_cast<double>(members.size()));
  }
  return vertex_of;
}

// The branches being traced: which pixel is which vertex, which chain pixels are walked.
struct SkeletonTrace {
  const PixelGraph& g;
  std::vector<int> vertex_of;
  std::vector<char> visited;
  SkeletonGraph& out;

  // Walks from `from` (a vertex pixel) through `first` until a vertex pixel; returns the
  // polyline and the end vertex (or a new one at a dead end).
  SkeletonGraph::Branch walk(size_t from, size_t first) {
    SkeletonGraph::Branch b;
    b.a = vertex_of[from];
    b.points.push_back(out.vertices[static_cast<size_t>(b.a)]);
    size_t prev = from, cur = first;
    while (true) {
      if (vertex_of[cur] >= 0) {
        b.b = vertex_of[cur];
        b.points.push_back(out.vertices[static_cast<size_t>(b.b)]);
        return b;
      }
      visited[cur] = 1;
      b.points.push_back(cv::Point2d(g.pixels[cur]));
      int next = -1;
      for (int q : g.adjacent[cur]) {
        if (static_cast<size_t>(q) == prev) continue;
        if (vertex_of[q] >= 0 || !visited[q]) {
          next = q;
          break;
        }
      }
      if (next < 0) {  // a loop closed on itself: end at this pixel as a new vertex
        vertex_of[cur] = static_cast<int>(out.vertices.size());
        out.vertices.push_back(cv::Point2d(g.pixels[cur]));
        b.b = vertex_of[cur];
        return b;
      }
      prev = cur;
      cur = static_cast<size_t>(next);
    }
  }

  // Every branch leaving a vertex pixel, in pixel order.
  void branches_from_vertices() {
    for (size_t i = 0; i < g.pixels.size(); ++i) {
      if (vertex_of[i] < 0) continue;
      for (int q : g.adjacent[i]) {
        const auto qs = static_cast<size_t>(q);
        if (vertex_of[qs] >= 0) {
          // Two vertex pixels side by side: one direct branch, added from the lower pixel.
          if (vertex_of[qs] != vertex_of[i] && i < qs) {
            out.branches.push_back(
                {vertex_of[i],
                 vertex_of[qs],
                 {out.vertices[static_cast<size_t>(vertex_of[i])], out.vertices[static_cast<size_t>(vertex_of[qs])]}});
          }
        } else if (!visited[qs]) {
          out.branches.push_back(walk(i, qs));
        }
      }
    }
  }

  // Closed loops without any vertex: make their first pixel one and walk around.
  void closed_loops(const std::vector<int>& degree) {
    for (size_t i = 0; i < g.pixels.size(); ++i) {
      if (degree[i] != 2 || visited[i] || vertex_of[i] >= 0) continue;
      vertex_of[i] = static_cast<int>(out.vertices.size());
      out.vertices.push_back(cv::Point2d(g.pixels[i]));
      visited[i] = 1;
      const auto first = static_cast<size_t>(g.adjacent[i][0]);
      if (!visited[first]) out.branches.push_back(walk(i, first));
    }
  }
};

}  // namespace

SkeletonGraph trace_skeleton(const cv::Mat& skeleton) {
  const PixelGraph g = pixel_graph(skeleton);
  const size_t n = g.pixels.size();
  std::vector<int> degree(n);
  for (size_t i = 0; i < n; ++i) degree[i] = static_cast<int>(g.adjacent[i].size());
  SkeletonGraph out;
  SkeletonTrace trace{g, group_vertices(g, degree, out), std::vector<char>(n, 0), out};
  trace.branches_from_vertices();
  trace.closed_loops(degree);
  return out;
}

void prune_spurs(SkeletonGraph& graph, double min_length_px) {
  std::vector<int> ends(graph.vertices.size(), 0);
  for (const auto& b : graph.branches) {
    ++ends[static_cast<size_t>(b.a)];
    ++ends[static_cast<size_t>(b.b)];
  }
  std::vector<SkeletonGraph::Branch> kept;
  for (auto& b : graph.branches) {
    const bool dangling = ends[static_cast<size_t>(b.a)] == 1 || ends[static_cast<size_t>(b.b)] == 1;
    const bool isolated = ends[static_cast<size_t>(b.a)] == 1 && ends[static_cast<size_t>(b.b)] == 1;
    // A spur hangs off a junction; an isolated short piece is kept for the scores to judge.
    if (dangling && !isolated && polyline_length(b.points) < min_length_px) continue;
    kept.push_back(std::move(b));
  }
  graph.branches = std::move(kept);
  drop_unused_vertices(graph);
}

void drop_unused_vertices(SkeletonGraph& graph) {
  // Renumber the vertices still used, in the order the branches first use them.
  std::vector<int> remap(graph.vertices.size(), -1);
  std::vector<cv::Point2d> vertices;
  for (auto& b : graph.branches) {
    for (int* v : {&b.a, &b.b}) {
      if (remap[static_cast<size_t>(*v)] < 0) {
        remap[static_cast<size_t>(*v)] = static_cast<int>(vertices.size());
        vertices.push_back(graph.vertices[static_cast<size_t>(*v)]);
      }
      *v = remap[static_cast<size_t>(*v)];
    }
  }
  graph.vertices = std::move(vertices);
}

AnchorGraph place_anchors(const SkeletonGraph& skeleton, double spacing_px, double simplify_tolerance_px) {
  AnchorGraph out;
  for (const auto& v : skeleton.vertices) out.nodes.push_back({v.x, v.y});
  for (const auto& b : skeleton.branches) {
    std::vector<cv::Point2d> simple;
    if (b.points.size() > 2 && simplify_tolerance_px > 0.0) {
      // approxPolyDP takes float points; pixel coordinates are exact in float.
      std::vector<cv::Point2f> in(b.points.begin(), b.points.end()), kept;
      cv::approxPolyDP(in, kept, simplify_tolerance_px, /*closed=*/false);
      simple.assign(kept.begin(), kept.end());
      // Keep the exact vertex positions at both ends (junction means are not integers).
      simple.front() = b.points.front();
      simple.back() = b.points.back();
    } else {
      simple = b.points;
    }
    if (b.a == b.b && polyline_length(simple) < 2.0 * spacing_px) continue;  // a tiny loop
    int prev = b.a;
    for (size_t k = 1; k < simple.size(); ++k) {
      const cv::Point2d p = simple[k - 1], q = simple[k];
      const int pieces = std::max(1, static_cast<int>(std::ceil(cv::norm(q - p) / spacing_px - 1e-9)));
      for (int s = 1; s <= pieces; ++s) {
        int node;
        if (k + 1 == simple.size() && s == pieces) {
          node = b.b;
        } else {
          const cv::Point2d r = p + (q - p) * (static_cast<double>(s) / pieces);
          node = static_cast<int>(out.nodes.size());
          out.nodes.push_back({r.x, r.y});
        }
        if (node != prev) out.pairs.push_back({prev, node});
        prev = node;
      }
    }
  }
  return out;
}

AnchorGraph skeleton_anchors(const cv::Mat& likelihood, const SkeletonOptions& options) {
  cv::Mat smooth = likelihood;
  if (options.smooth_sigma_px > 0.0) cv::GaussianBlur(likelihood, smooth, {0, 0}, options.smooth_sigma_px);
  const cv::Mat mask = drop_small_components(smooth >= options.threshold, options.min_component_px);
  SkeletonGraph skeleton = trace_skeleton(thin(mask));
  prune_spurs(skeleton, options.min_spur_px);
  if (options.split_crossings) split_crossings(skeleton, {options.crossing_tolerance_deg, options.crossing_merge_px});
  return place_anchors(skeleton, options.anchor_spacing_px, options.simplify_tolerance_px);
}

void declare_crossing_options(options::Table<SkeletonOptions>& t) {
  t.boolean("split_crossings", &SkeletonOptions::split_crossings)
      .help("A skeleton junction whose branches pair into straight lines becomes crossing lines with no shared node");
  t.number("crossing_tolerance_deg", &SkeletonOptions::crossing_tolerance_deg)
      .unit("deg")
      .range(options::between(0, 90))
      .help("split_crossings: largest bend of a straight-through pair of branches (180 deg minus their angle)");
  t.number("crossing_merge_px", &SkeletonOptions::crossing_merge_px)
      .unit("px")
      .range(options::at_least(0))
      .help(
          "split_crossings: two 3-way junctions joined by a shorter branch are judged as one crossing (an X at a "
          "shallow angle)");
}

const options::Table<SkeletonOptions>& skeleton_option_table() {
  static const options::Table<SkeletonOptions> table = [] {
    options::Table<SkeletonOptions> t;
    declare_skeleton_options(t, "");
    declare_crossing_options(t);
    return t;
  }();
  return table;
}

void SkeletonOptions::validate() const { skeleton_option_table().check(*this); }

}  // namespace nsg::skeleton

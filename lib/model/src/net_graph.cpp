#include "nsg/model/net_graph.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <numeric>

#include "nsg/core/error.h"
#include "nsg/model/direction.h"

namespace nsg::model {

void NetGraphOptions::validate() const {
  NSG_CHECK(stride_px >= 1 && stride_px <= 64, ConfigError, "", "stride_px", "in [1, 64]");
  NSG_CHECK(anchor_threshold > 0.0 && anchor_threshold < 1.0, ConfigError, "", "anchor_threshold", "in (0, 1)");
  NSG_CHECK(nms_radius_px >= 0.0, ConfigError, "", "nms_radius_px", "≥ 0");
  NSG_CHECK(vote_radius_cells >= 0 && vote_radius_cells <= 8, ConfigError, "", "vote_radius_cells", "in [0, 8]");
  NSG_CHECK(pair_radius_px > 0.0, ConfigError, "", "pair_radius_px", "> 0");
  NSG_CHECK(segment_samples >= 3 && segment_samples <= 64, ConfigError, "", "segment_samples", "in [3, 64]");
  NSG_CHECK(min_connection_score >= 0.0 && min_connection_score <= 1.0, ConfigError, "", "min_connection_score",
            "in [0, 1]");
  NSG_CHECK(shortcut_radius_px >= 0.0, ConfigError, "", "shortcut_radius_px", "≥ 0 (0 = off)");
  extraction.validate();
}

double px_to_cell(double px, int stride_px) { return (px - (stride_px - 1) / 2.0) / stride_px; }

float sample_clamped(const cv::Mat& map, double cu, double cv) {
  const int w = map.cols, h = map.rows;
  cu = std::clamp(cu, 0.0, w - 1.0);
  cv = std::clamp(cv, 0.0, h - 1.0);
  const int u0 = std::min(static_cast<int>(std::floor(cu)), std::max(w - 2, 0));
  const int v0 = std::min(static_cast<int>(std::floor(cv)), std::max(h - 2, 0));
  const int u1 = std::min(u0 + 1, w - 1), v1 = std::min(v0 + 1, h - 1);
  // float arithmetic in the order of the PyTorch twin (nsgraph.models.lanegraphnet._bilinear)
  const float fu = static_cast<float>(cu - u0), fv = static_cast<float>(cv - v0);
  auto at = [&](int v, int u) { return map.at<float>(v, u); };
  return (1 - fv) * ((1 - fu) * at(v0, u0) + fu * at(v0, u1)) + fv * ((1 - fu) * at(v1, u0) + fu * at(v1, u1));
}

namespace {

void check_maps(const NetMaps& m) {
  NSG_CHECK(m.heat.type() == CV_32F && !m.heat.empty(), DataError, "", "anchor heatmap", "a CV_32F map");
  for (const cv::Mat* x : {&m.offset_u, &m.offset_v})
    NSG_CHECK(x->type() == CV_32F && x->size() == m.heat.size(), DataError, "", "anchor offset",
              "CV_32F maps of the heatmap's size");
  NSG_CHECK(m.direction.size() == static_cast<size_t>(kDirectionClasses), DataError, "", "direction maps",
            std::to_string(kDirectionClasses) + " class maps");
  for (const cv::Mat& d : m.direction)
    NSG_CHECK(d.type() == CV_32F && d.size() == m.heat.size(), DataError, "", "direction maps",
              "CV_32F maps of the heatmap's size");
  NSG_CHECK(m.tile_size_px > 0, DataError, "", "tile size", "> 0 px");
}

bool is_peak(const cv::Mat& heat, int r, int c) {
  const float x = heat.at<float>(r, c);
  for (int dr = -1; dr <= 1; ++dr) {
    for (int dc = -1; dc <= 1; ++dc) {
      const int rr = r + dr, cc = c + dc;
      if ((dr || dc) && rr >= 0 && cc >= 0 && rr < heat.rows && cc < heat.cols && heat.at<float>(rr, cc) > x)
        return false;
    }
  }
  return true;
}

}  // namespace

AnchorSet net_anchors(const NetMaps& maps, const NetGraphOptions& o) {
  o.validate();
  check_maps(maps);
  // Heat on a grid of 1/4096: runtimes (OpenCV dnn, PyTorch) differ in the last bits, and
  // near-equal neighbours or a value at the threshold must be decided alike by both.
  cv::Mat heat(maps.heat.size(), CV_32F);
  for (int r = 0; r < heat.rows; ++r)
    for (int c = 0; c < heat.cols; ++c)
      heat.at<float>(r, c) = std::round(maps.heat.at<float>(r, c) * 4096.0f) / 4096.0f;
  struct Candidate {
    float score;
    int r, c;
  };
  std::vector<Candidate> cands;
  for (int r = 0; r < heat.rows; ++r)
    for (int c = 0; c < heat.cols; ++c)
      if (heat.at<float>(r, c) >= o.anchor_threshold && is_peak(heat, r, c))
        cands.push_back({heat.at<float>(r, c), r, c});
  std::stable_sort(cands.begin(), cands.end(),
                   [](const Candidate& a, const Candidate& b) { return a.score > b.score; });
  AnchorSet out;
  std::vector<std::array<int, 2>> cells;
  const double last = maps.tile_size_px - 1.0, half = (o.stride_px - 1) / 2.0;
  for (const Candidate& k : cands) {
    const double u =
        std::clamp((k.c + static_cast<double>(maps.offset_u.at<float>(k.r, k.c))) * o.stride_px + half, 0.0, last);
    const double v =
        std::clamp((k.r + static_cast<double>(maps.offset_v.at<float>(k.r, k.c))) * o.stride_px + half, 0.0, last);
    bool near = false;
    for (const auto& p : out.points) near = near || std::hypot(p[0] - u, p[1] - v) < o.nms_radius_px;
    if (near) continue;
    out.points.push_back({u, v});
    out.scores.push_back(k.score);
    cells.push_back({k.r, k.c});
  }
  // Row-major cell order, not score order: two runtimes' last-bit differences in the heat
  // must not reorder the nodes.
  std::vector<size_t> order(cells.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return cells[a] < cells[b]; });
  AnchorSet sorted;
  std::vector<std::array<int, 2>> sorted_cells;
  for (size_t i : order) {
    sorted.points.push_back(out.points[i]);
    sorted.scores.push_back(out.scores[i]);
    sorted_cells.push_back(cells[i]);
  }
  out = std::move(sorted);
  cells = std::move(sorted_cells);
  for (const auto& [r, c] : cells) {
    Votes votes{};
    for (int rr = std::max(0, r - o.vote_radius_cells); rr <= std::min(heat.rows - 1, r + o.vote_radius_cells); ++rr)
      for (int cc = std::max(0, c - o.vote_radius_cells); cc <= std::min(heat.cols - 1, c + o.vote_radius_cells); ++cc)
        for (int k = 0; k < kDirectionClasses; ++k)
          votes[static_cast<size_t>(k)] += maps.direction[static_cast<size_t>(k)].at<float>(rr, cc);
    out.votes.push_back(votes);
    out.mean_dir.push_back(mean_direction_px(votes));
  }
  return out;
}

cv::Mat net_pair_inputs(const std::vector<cv::Mat>& features, const std::vector<std::array<double, 2>>& points,
                        const std::vector<std::array<int, 2>>& pairs, const NetGraphOptions& o) {
  o.validate();
  NSG_CHECK(!features.empty(), DataError, "", "pair features", "at least one channel");
  for (const cv::Mat& f : features)
    NSG_CHECK(f.type() == CV_32F && f.size() == features[0].size(), DataError, "", "pair features",
              "CV_32F maps of one size");
  const int channels = static_cast<int>(features.size()), samples = o.segment_samples;
  cv::Mat out(static_cast<int>(pairs.size()), 4 * channels + 1, CV_32F);
  std::vector<float> s(static_cast<size_t>(samples) * channels);
  for (size_t k = 0; k < pairs.size(); ++k) {
    for (int i : pairs[k])
      NSG_CHECK(i >= 0 && static_cast<size_t>(i) < points.size(), DataError, "", "pairs[" + std::to_string(k) + "]",
                "anchor indices in [0, " + std::to_string(points.size()) + ")");
    const auto& a = points[static_cast<size_t>(pairs[k][0])];
    const auto& b = points[static_cast<size_t>(pairs[k][1])];
    for (int t = 0; t < samples; ++t) {
      const double f = static_cast<double>(t) / (samples - 1);
      const double cu = px_to_cell(a[0] + (b[0] - a[0]) * f, o.stride_px);
      const double cv = px_to_cell(a[1] + (b[1] - a[1]) * f, o.stride_px);
      for (int c = 0; c < channels; ++c)
        s[static_cast<size_t>(t * channels + c)] = sample_clamped(features[static_cast<size_t>(c)], cu, cv);
    }
    float* row = out.ptr<float>(static_cast<int>(k));
    for (int c = 0; c < channels; ++c) {
      const float fa = s[static_cast<size_t>(c)], fb = s[static_cast<size_t>((samples - 1) * channels + c)];
      float sum = 0.0f, mx = -std::numeric_limits<float>::infinity();
      for (int t = 1; t + 1 < samples; ++t) {
        sum += s[static_cast<size_t>(t * channels + c)];
        mx = std::max(mx, s[static_cast<size_t>(t * channels + c)]);
      }
      row[c] = fa + fb;
      row[channels + c] = std::fabs(fa - fb);
      row[2 * channels + c] = sum / static_cast<float>(samples - 2);
      row[3 * channels + c] = mx;
    }
    row[4 * channels] = static_cast<float>(std::hypot(b[0] - a[0], b[1] - a[1]) / o.pair_radius_px);
  }
  return out;
}

std::vector<bool> non_shortcut_pairs(const std::vector<std::array<double, 2>>& points,
                                     const std::vector<std::array<int, 2>>& pairs, double radius_px) {
  std::vector<bool> keep(pairs.size(), true);
  if (radius_px <= 0.0) return keep;
  std::vector<std::vector<int>> neighbours(points.size());
  for (const auto& p : pairs) {
    neighbours[static_cast<size_t>(p[0])].push_back(p[1]);
    neighbours[static_cast<size_t>(p[1])].push_back(p[0]);
  }
  for (auto& n : neighbours) std::sort(n.begin(), n.end());
  std::vector<int> common;
  for (size_t k = 0; k < pairs.size(); ++k) {
    const auto& a = points[static_cast<size_t>(pairs[k][0])];
    const auto& c = points[static_cast<size_t>(pairs[k][1])];
    const double du = c[0] - a[0], dv = c[1] - a[1], length2 = du * du + dv * dv;
    if (length2 <= 0.0) continue;
    const auto& na = neighbours[static_cast<size_t>(pairs[k][0])];
    const auto& nc = neighbours[static_cast<size_t>(pairs[k][1])];
    common.clear();
    std::set_intersection(na.begin(), na.end(), nc.begin(), nc.end(), std::back_inserter(common));
    for (int m : common) {
      const auto& b = points[static_cast<size_t>(m)];
      const double t = ((b[0] - a[0]) * du + (b[1] - a[1]) * dv) / length2;
      if (t <= 0.0 || t >= 1.0) continue;
      if (std::hypot(a[0] + t * du - b[0], a[1] + t * dv - b[1]) <= radius_px) {
        keep[k] = false;
        break;
      }
    }
  }
  return keep;
}

metrics::Graph net_graph(const AnchorSet& anchors, const std::vector<std::array<int, 2>>& pairs,
                         const std::vector<double>& pair_scores, int tile_size_px, const NetGraphOptions& o) {
  o.validate();
  NSG_CHECK(pair_scores.size() == pairs.size(), DataError, "", "pair scores", "one per candidate pair");
  NSG_CHECK(anchors.votes.size() == anchors.points.size() && anchors.scores.size() == anchors.points.size(), DataError,
            "", "anchors", "a score and votes per anchor");
  AnchorGraph kept;
  kept.nodes = anchors.points;
  std::vector<double> kept_scores;
  for (size_t k = 0; k < pairs.size(); ++k) {
    for (int i : pairs[k])
      NSG_CHECK(i >= 0 && static_cast<size_t>(i) < anchors.points.size(), DataError, "",
                "pairs[" + std::to_string(k) + "]",
                "anchor indices in [0, " + std::to_string(anchors.points.size()) + ")");
    if (pair_scores[k] < o.min_connection_score) continue;
    kept.pairs.push_back(pairs[k]);
    kept_scores.push_back(pair_scores[k]);
  }
  const std::vector<bool> keep = non_shortcut_pairs(kept.nodes, kept.pairs, o.shortcut_radius_px);
  size_t n = 0;
  for (size_t k = 0; k < keep.size(); ++k)
    if (keep[k]) {
      kept.pairs[n] = kept.pairs[k];
      kept_scores[n++] = kept_scores[k];
    }
  kept.pairs.resize(n);
  kept_scores.resize(n);
  // The rule and the direction angle as for the forests; the likelihood only feeds edge
  // scores, replaced by the pair scores.
  const cv::Mat no_likelihood = cv::Mat::zeros(tile_size_px, tile_size_px, CV_32F);
  const DirectionVotes cached = [&](const std::vector<std::array<double, 2>>&) { return anchors.votes; };
  std::vector<double> angle_deg;
  metrics::Graph g = orient_and_score(kept, no_likelihood, cached, &angle_deg);
  g.node_scores = anchors.scores;
  g.edge_scores = kept_scores;
  postprocess(g, tile_size_px, o.extraction, &angle_deg);
  return g;
}

}  // namespace nsg::model

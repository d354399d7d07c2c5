// DET_l and TOP_ll as OpenLane-V2's evaluator (openlanev2/centerline/evaluation/evaluate.py,
// distance.py) computes them, reimplemented from its rules (docs/metrics.md "Frames"). Where
// its numpy code rounds to float32 — ground-truth points, the relaxation factor, recalls,
// precisions and APs — so does this, because the 11-point interpolation compares float32
// recalls with the thresholds 0, 0.1, …, 1 in float32: 7/10 reaches 0.7 there, and would
// not reach 0.7000000000000001 in double.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>

#include "nsg/core/error.h"
#include "nsg/core/strings.h"
#include "nsg/metrics/frames.h"
#include "nsg/metrics/measure.h"
#include "nsg/metrics/numpy_order.h"
#include "nsg/metrics/params.h"

namespace nsg::metrics {
namespace {

constexpr std::array<double, 3> kThresholdsM = {1.0, 2.0, 3.0};      // centerlines, lane segments
constexpr std::array<double, 3> kAreaThresholdsM = {0.5, 1.0, 1.5};  // areas (THRESHOLDS_AREA)
constexpr double kRelationshipThreshold = 0.5;  // a link is predicted when its probability is above
constexpr double kUnset = 1024.0;               // the distance of a pair the Chamfer mask skips
const float kEps32 = std::numeric_limits<float>::epsilon();

using Curve = std::vector<Point3>;

// The wall-clock budget of a run (0 = none), checked before each frame's work as score()
// checks it before each tile: a host's last line of defence, since each frame is bounded by
// the results limits but a run of many frames is bounded only by this.
class Budget {
 public:
  Budget(double max_seconds, size_t frames)
      : max_seconds_(max_seconds), frames_(frames), start_(std::chrono::steady_clock::now()) {}

  // `done`: the frames whose measurement was finished, for the message.
  void check(size_t done) const {
    if (max_seconds_ <= 0) return;
    const std::chrono::duration<double> elapsed = std::chrono::steady_clock::now() - start_;
    NSG_CHECK(elapsed.count() < max_seconds_, ConfigError, "", "--max-seconds",
              strprintf("a run that scores its %zu frames within %g s (%zu measured when the budget ran out); raise "
                        "--max-seconds, or 0 for no limit",
                        frames_, max_seconds_, done));
  }

 private:
  double max_seconds_;
  size_t frames_;
  std::chrono::steady_clock::time_point start_;
};

double point_distance(const Point3& a, const Point3& b) {
  const double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

// distance.py chamfer_distance(gt, pred): a closed ground truth loses its repeated point.
double chamfer(const Curve& gt_in, const Curve& pred) {
  size_t n_gt = gt_in.size();
  if (n_gt > 1 && gt_in.front() == gt_in.back()) --n_gt;
  std::vector<double> gt_min(n_gt, std::numeric_limits<double>::infinity());
  double pred_sum = 0.0;
  for (const Point3& p : pred) {
    double best = std::numeric_limits<double>::infinity();
    for (size_t g = 0; g < n_gt; ++g) {
      const double d = point_distance(p, gt_in[g]);
      best = std::min(best, d);
      gt_min[g] = std::min(gt_min[g], d);
    }
    pred_sum += best;
  }
  const double gt_sum = std::accumulate(gt_min.begin(), gt_min.end(), 0.0);
  return (pred_sum / static_cast<double>(pred.size()) + gt_sum / static_cast<double>(n_gt)) / 2.0;
}

// The discrete Fréchet distance (Eiter & Mannila), Euclidean, one row at a time.
double frechet(const Curve& a, const Curve& b) {
  std::vector<double> prev(b.size()), row(b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    for (size_t j = 0; j < b.size(); ++j) {
      const double d = point_distance(a[i], b[j]);
      double reach;
      if (i == 0 && j == 0) reach = d;
      else if (i == 0) reach = row[j - 1];
      else if (j == 0) reach = prev[0];
      else reach = std::min({prev[j], prev[j - 1], row[j - 1]});
      row[j] = std::max(reach, d);
    }
    std::swap(prev, row);
  }
  return prev.back();
}

// pairwise(..., relax=True): the factor max(0.5, 1 − 0.005 · d) of the ground truth's
// nearest point to the ego, d and the factor in float32 as numpy has them.
float relaxation(const Curve& gt) {
  float nearest = std::numeric_limits<float>::infinity();
  for (const Point3& p : gt) {
    const float x = static_cast<float>(p[0]), y = static_cast<float>(p[1]), z = static_cast<float>(p[2]);
    nearest = std::min(nearest, std::sqrt(x * x + y * y + z * z));
  }
  const float f = 1.0f - 0.005f * nearest;
  return std::max(0.5f, f);
}

// The frame's ground truth × prediction distances: relaxed Fréchet where the relaxed
// Chamfer is below the largest threshold, else kUnset.
std::vector<double> distance_matrix(const std::vector<Curve>& gt, const std::vector<Curve>& pred) {
  std::vector<double> out(gt.size() * pred.size(), kUnset);
  for (size_t g = 0; g < gt.size(); ++g) {
    const double factor = relaxation(gt[g]);
    for (size_t p = 0; p < pred.size(); ++p)
      if (chamfer(gt[g], pred[p]) * factor < kThresholdsM.back())
        out[g * pred.size() + p] = frechet(pred[p], gt[g]) * factor;
  }
  return out;
}

// Indices by descending value as the evaluator's np.argsort(-values) gives them, equal
// values included (numpy's introsort, nsg/metrics/numpy_order.h).
std::vector<size_t> order_by_descending(const std::vector<double>& values) { return numpy_argsort_descending(values); }

struct FrameMatch {
  std::vector<uint8_t> tp;          // per prediction
  std::vector<int64_t> matched_gt;  // per prediction, −1 = none
};

// _tpfp: predictions by confidence take their nearest ground truth when it is within the
// threshold and not yet taken; a prediction whose nearest is taken is a false positive.
FrameMatch match_frame(size_t n_gt, const std::vector<double>& confidence, const std::vector<double>& dist,
                       double threshold) {
  const size_t n_pred = confidence.size();
  FrameMatch m{std::vector<uint8_t>(n_pred, 0), std::vector<int64_t>(n_pred, -1)};
  if (n_gt == 0 || n_pred == 0) return m;
  std::vector<uint8_t> covered(n_gt, 0);
  for (const size_t p : order_by_descending(confidence)) {
    size_t best = 0;
    for (size_t g = 1; g < n_gt; ++g)
      if (dist[g * n_pred + p] < dist[best * n_pred + p]) best = g;
    if (dist[best * n_pred + p] < threshold && !covered[best]) {
      covered[best] = 1;
      m.tp[p] = 1;
      m.matched_gt[p] = static_cast<int64_t>(best);
    }
  }
  return m;
}

// _pr_curve: 11-point interpolated AP, in float32 like the evaluator's arrays.
float eleven_point_ap(const std::vector<float>& recalls, const std::vector<float>& precisions) {
  float ap = 0.0f;
  for (int k = 0; k <= 10; ++k) {
    // np.arange(0, 1 + 1e-3, 0.1) (0.30000000000000004, 0.7000000000000001, …) against a
    // float32 array: numpy compares in float32, so 7/10 in float32 reaches 0.7.
    const float threshold = static_cast<float>(k * 0.1);
    float best = 0.0f;
    for (size_t i = 0; i < recalls.size(); ++i)
      if (recalls[i] >= threshold) best = std::max(best, precisions[i]);
    ap += best;
  }
  return ap / 11.0f;
}

// One frame's detections at one kind (centerlines, lane segments, areas of a category):
// its ground-truth count, the predictions' confidences and the n_gt × n_pred distances.
struct FrameDetections {
  size_t n_gt = 0;
  std::vector<double> confidence;
  std::vector<double> dist;
  // For the topology (rule 7): n_gt × n_gt and n_pred × n_pred, row-major; unset for areas.
  const std::vector<double>* gt_topology = nullptr;
  const std::vector<double>* pred_topology = nullptr;
};

// _AP at one threshold over every frame; fills each frame's matches for the topology.
float average_precision(const std::vector<FrameDetections>& frames, double threshold,
                        std::vector<FrameMatch>* matches) {
  std::vector<double> confidence;
  std::vector<uint8_t> tp;
  int64_t n_gt = 0;
  for (size_t f = 0; f < frames.size(); ++f) {
    const FrameDetections& d = frames[f];
    FrameMatch m = match_frame(d.n_gt, d.confidence, d.dist, threshold);
    confidence.insert(confidence.end(), d.confidence.begin(), d.confidence.end());
    tp.insert(tp.end(), m.tp.begin(), m.tp.end());
    n_gt += static_cast<int64_t>(d.n_gt);
    if (matches) (*matches)[f] = std::move(m);
  }
  if (tp.empty() && n_gt == 0) return 1.0f;
  std::vector<float> recalls, precisions;
  float tps = 0.0f, fps = 0.0f;
  const float gt_count = std::max(static_cast<float>(n_gt), kEps32);
  for (const size_t i : order_by_descending(confidence)) {
    (tp[i] ? tps : fps) += 1.0f;
    recalls.push_back(tps / gt_count);
    precisions.push_back(tps / std::max(tps + fps, kEps32));
  }
  return eleven_point_ap(recalls, precisions);
}

// _average_precision_per_vertex: the ranked predicted neighbours against the true ones.
float vertex_ap(const std::vector<size_t>& truth, const std::vector<size_t>& predicted,
                const std::vector<double>& confidence) {
  if (truth.empty() && predicted.empty()) return 1.0f;
  if (truth.empty() || predicted.empty()) return 0.0f;
  float tp = 0.0f, fp = 0.0f, sum = 0.0f;
  for (const size_t i : order_by_descending(confidence)) {
    const bool hit = std::find(truth.begin(), truth.end(), predicted[i]) != truth.end();
    (hit ? tp : fp) += 1.0f;
    if (hit) sum += tp / std::max(tp + fp, kEps32);
  }
  return sum / static_cast<float>(truth.size());
}

// _AP_directerd: every vertex's outgoing row, then every incoming column.
void directed_aps(const std::vector<double>& gt, const std::vector<double>& pred, size_t n, std::vector<double>* out) {
  for (int pass = 0; pass < 2; ++pass)
    for (size_t v = 0; v < n; ++v) {
      std::vector<size_t> truth, predicted;
      std::vector<double> confidence;
      for (size_t w = 0; w < n; ++w) {
        const size_t at = pass == 0 ? v * n + w : w * n + v;
        if (gt[at] != 0.0) truth.push_back(w);
        if (pred[at] > kRelationshipThreshold) {
          predicted.push_back(w);
          confidence.push_back(pred[at]);
        }
      }
      out->push_back(vertex_ap(truth, predicted, confidence));
    }
}

// _mAP_topology_lclc for one frame at one threshold: the prediction's links between
// matched centerlines carried onto the ground truth's; every other pair predicted as "no
// link" where the truth has one and as a link of probability 0.5 + float32 ε where it has
// none (the evaluator's v1.1 rule: an unmatched pair costs).
void frame_topology_aps(const std::vector<double>& gt_topology, size_t n, const std::vector<double>& pred_topology,
                        size_t n_pred, const FrameMatch& m, std::vector<double>* out) {
  if (n == 0) return;
  std::vector<double> carried(n * n, std::numeric_limits<double>::quiet_NaN());
  for (size_t a = 0; a < n_pred; ++a) {
    if (m.matched_gt[a] < 0) continue;
    for (size_t b = 0; b < n_pred; ++b) {
      if (m.matched_gt[b] < 0) continue;
      carried[static_cast<size_t>(m.matched_gt[a]) * n + static_cast<size_t>(m.matched_gt[b])] =
          pred_topology[a * n_pred + b];
    }
  }
  const double unmatched_link = 0.5 + static_cast<double>(kEps32);
  for (size_t i = 0; i < n * n; ++i)
    if (std::isnan(carried[i])) carried[i] = (1.0 - gt_topology[i]) * unmatched_link;
  directed_aps(gt_topology, carried, n, out);
}

struct LaneScores {
  std::array<double, 3> det_per_threshold{};
  double det = 0.0;
  double top = 0.0;
};

// DET (rule 6 at 1, 2 and 3 m, averaged in float32) and TOP (rule 7 on each threshold's
// matches, averaged over every vertex AP; 0 when there is none) of centerlines or lane segments.
LaneScores lane_scores(const std::vector<FrameDetections>& frames, const Budget& budget) {
  LaneScores s;
  std::vector<double> vertex_aps;
  float det_sum = 0.0f;
  for (size_t t = 0; t < kThresholdsM.size(); ++t) {
    std::vector<FrameMatch> matches(frames.size());
    const float ap = average_precision(frames, kThresholdsM[t], &matches);
    s.det_per_threshold[t] = ap;
    det_sum += ap;
    for (size_t f = 0; f < frames.size(); ++f) {
      budget.check(f);
      const FrameDetections& d = frames[f];
      frame_topology_aps(*d.gt_topology, d.n_gt, *d.pred_topology, d.confidence.size(), matches[f], &vertex_aps);
    }
  }
  s.det = det_sum / 3.0f;
  double top_sum = 0.0;
  for (const double v : vertex_aps) top_sum += v;
  s.top = vertex_aps.empty() ? 0.0 : top_sum / static_cast<double>(vertex_aps.size());
  return s;
}

// A coordinate rounded to float32. Not inlined on purpose: GCC 12.2 at -O3 vectorizes the
// loop below into code that leaves the last points of a lane unrounded (found by the
// golden pred-ties-distinct.json: 2 of its 50 frames matched another ground truth), and a
// call it cannot see through keeps every value rounded.
[[gnu::noinline]] double round_to_float32(double v) { return static_cast<double>(static_cast<float>(v)); }

// The evaluator reads ground-truth points as float32 (collect(): np.float32).
FrameCenterlines as_float32(const FrameCenterlines& f) {
  FrameCenterlines out = f;
  for (Curve& lane : out.lanes)
    for (Point3& p : lane)
      for (double& c : p) c = round_to_float32(c);
  return out;
}

// The graph metrics reported for frames, in report order.
constexpr std::array<int, 6> kFrameGraphMetrics = {kApls,  kAplsDirected, kDirectionAccuracy,
                                                   kGeoF1, kTopoF1,       kTopoDirectedF1};

// nsgraph's metrics per frame as a tile, macro means over frames (the frame's masks are
// not meaningful — its extent is not a tile's — so they are computed on a 1-pixel square).
std::vector<std::pair<std::string, std::optional<double>>> graph_means(
    const FrameSet& truth, const std::vector<const FrameCenterlines*>& preds, const Budget& budget) {
  MetricParams params;
  params.size_px = 1;
  std::array<double, 6> sums{};
  std::array<int64_t, 6> defined{};
  for (size_t f = 0; f < truth.size(); ++f) {
    budget.check(f);
    const Graph gt = frame_graph(truth[f].second, true);
    const Graph pred = frame_graph(*preds[f], false);
    const TileMeasurement m = measure(truth[f].first, gt, &pred, params);
    for (size_t k = 0; k < kFrameGraphMetrics.size(); ++k)
      if (const std::optional<double>& v = m.values[static_cast<size_t>(kFrameGraphMetrics[k])]) {
        sums[k] += *v;
        ++defined[k];
      }
  }
  std::vector<std::pair<std::string, std::optional<double>>> out;
  for (size_t k = 0; k < kFrameGraphMetrics.size(); ++k)
    out.emplace_back(metric_name(kFrameGraphMetrics[k]),
                     defined[k] ? std::optional<double>(sums[k] / static_cast<double>(defined[k])) : std::nullopt);
  return out;
}

nlohmann::ordered_json graph_json(const FramesReport& r) {
  nlohmann::ordered_json out = nlohmann::ordered_json::object();
  for (const auto& [name, value] : r.graph_means) out[name] = value ? nlohmann::ordered_json(*value) : nullptr;
  return out;
}

// lanesegment/evaluation/distance.py lane_segment_distance: half the sum of the
// centerlines' Fréchet distance and the lanelines' Chamfer distances.
double lane_segment_distance(const SegmentLines& gt, const SegmentLines& pred) {
  return 0.5 * (frechet(gt.centerline, pred.centerline) + chamfer(gt.left, pred.left) + chamfer(gt.right, pred.right));
}

// Its pairwise(..., relax=True) masked where the relaxed centerline Chamfer is not below the
// largest threshold (kUnset there), as for centerlines.
std::vector<double> segment_distances(const std::vector<SegmentLines>& gt, const std::vector<SegmentLines>& pred) {
  std::vector<double> out(gt.size() * pred.size(), kUnset);
  for (size_t g = 0; g < gt.size(); ++g) {
    const double factor = relaxation(gt[g].centerline);
    for (size_t p = 0; p < pred.size(); ++p)
      if (chamfer(gt[g].centerline, pred[p].centerline) * factor < kThresholdsM.back())
        out[g * pred.size() + p] = lane_segment_distance(gt[g], pred[p]) * factor;
  }
  return out;
}

// DET_a's detections of one category in a frame: the areas of that category, Chamfer
// distances unrelaxed and unmasked (area_distance).
FrameDetections area_detections(const FrameCenterlines& gt, const FrameCenterlines& pred, int category) {
  std::vector<const AreaPoints*> g, p;
  FrameDetections d;
  for (const AreaPoints& a : gt.areas)
    if (a.category == category) g.push_back(&a);
  for (size_t k = 0; k < pred.areas.size(); ++k)
    if (pred.areas[k].category == category) {
      p.push_back(&pred.areas[k]);
      d.confidence.push_back(pred.area_confidence[k]);
    }
  d.n_gt = g.size();
  d.dist.reserve(g.size() * p.size());
  for (const AreaPoints* a : g)
    for (const AreaPoints* b : p) d.dist.push_back(chamfer(a->points, b->points));
  return d;
}

// DET_ls, DET_a, TOP_lsls and the score as lanesegment/evaluation/evaluate.py computes them.
void score_map_elements(const FrameSet& truth, const std::vector<const FrameCenterlines*>& preds, const Budget& budget,
                        FramesReport& r) {
  r.has_lane_segments = true;
  std::vector<FrameDetections> segments;
  for (size_t f = 0; f < truth.size(); ++f) {
    budget.check(f);
    const FrameCenterlines& gt = truth[f].second;
    segments.push_back({gt.segments.size(), preds[f]->segment_confidence,
                        segment_distances(gt.segments, preds[f]->segments), &gt.topology_lsls,
                        &preds[f]->topology_lsls});
    r.gt_lane_segments += static_cast<int64_t>(gt.segments.size());
    r.pred_lane_segments += static_cast<int64_t>(preds[f]->segments.size());
    r.gt_areas += static_cast<int64_t>(gt.areas.size());
    r.pred_areas += static_cast<int64_t>(preds[f]->areas.size());
  }
  const LaneScores ls = lane_scores(segments, budget);
  r.det_ls_per_threshold = ls.det_per_threshold;
  r.det_ls = ls.det;
  r.top_lsls = ls.top;
  // DET_a: per category (AREA_CATEGOTY: pedestrian crossing, road boundary) the APs at
  // 0.5, 1, 1.5 m, all six averaged in float32 as np.hstack(...).mean() does.
  float area_sum = 0.0f;
  for (size_t c = 0; c < 2; ++c) {
    std::vector<FrameDetections> areas;
    for (size_t f = 0; f < truth.size(); ++f)
      areas.push_back(area_detections(truth[f].second, *preds[f], static_cast<int>(c) + 1));
    float category_sum = 0.0f;
    for (size_t t = 0; t < kAreaThresholdsM.size(); ++t) {
      const float ap = average_precision(areas, kAreaThresholdsM[t], nullptr);
      area_sum += ap;
      category_sum += ap;
    }
    r.det_a_per_category[c] = category_sum / 3.0f;
  }
  r.det_a = area_sum / 6.0f;
  // The evaluator's 'score': the mean of DET_l (its lane segments), DET_a, DET_t,
  // sqrt(TOP_ll) and sqrt(TOP_lt). Without traffic elements its DET_t is 1 (an AP with no
  // ground truth and no prediction) and its TOP_lt 0 (no frame has a lane–element matrix).
  constexpr double kDetT = 1.0, kTopLt = 0.0;
  r.ls_score = (r.det_ls + r.det_a + kDetT + std::sqrt(r.top_lsls) + std::sqrt(kTopLt)) / 5.0;
}

}  // namespace

Graph frame_graph(const FrameCenterlines& frame, bool truth) {
  constexpr double kPxPerM = 5.0;  // 0.2 m a pixel, as the tiles
  // A link whose ends lie within this of each other joins the two centerlines at one node,
  // as the lane graph joins lanes (APLS rule 3's distance); a farther one is an edge.
  constexpr double kJoinM = 0.01;
  std::vector<Point3> points;
  std::vector<std::array<int64_t, 2>> chain_edges, link_edges;
  std::vector<int64_t> first, last;
  for (const Curve& lane : frame.lanes) {
    first.push_back(static_cast<int64_t>(points.size()));
    for (size_t i = 0; i < lane.size(); ++i) {
      if (i > 0) chain_edges.push_back({static_cast<int64_t>(points.size()) - 1, static_cast<int64_t>(points.size())});
      points.push_back(lane[i]);
    }
    last.push_back(static_cast<int64_t>(points.size()) - 1);
  }
  // Joined ends share their lowest-numbered node (union-find on node indices).
  std::vector<int64_t> parent(points.size());
  std::iota(parent.begin(), parent.end(), int64_t{0});
  const auto root = [&parent](int64_t x) {
    while (parent[static_cast<size_t>(x)] != x)
      x = parent[static_cast<size_t>(x)] = parent[static_cast<size_t>(parent[static_cast<size_t>(x)])];
    return x;
  };
  const size_t n = frame.lanes.size();
  for (size_t a = 0; a < n; ++a)
    for (size_t b = 0; b < n; ++b) {
      const double v = frame.topology[a * n + b];
      if (!(truth ? v == 1.0 : v > kRelationshipThreshold)) continue;
      const Point3& p = points[static_cast<size_t>(last[a])];
      const Point3& q = points[static_cast<size_t>(first[b])];
      if (std::hypot(p[0] - q[0], p[1] - q[1]) <= kJoinM) {
        const int64_t ra = root(last[a]), rb = root(first[b]);
        parent[static_cast<size_t>(std::max(ra, rb))] = std::min(ra, rb);
      } else {
        link_edges.push_back({last[a], first[b]});
      }
    }
  Graph g;
  std::vector<int64_t> index(points.size(), -1);
  for (size_t i = 0; i < points.size(); ++i) {
    const int64_t r = root(static_cast<int64_t>(i));
    if (index[static_cast<size_t>(r)] < 0) {
      index[static_cast<size_t>(r)] = static_cast<int64_t>(g.nodes.size());
      g.nodes.push_back({points[static_cast<size_t>(r)][0] * kPxPerM, -points[static_cast<size_t>(r)][1] * kPxPerM});
    }
    index[i] = index[static_cast<size_t>(r)];
  }
  for (const auto& edges : {chain_edges, link_edges})
    for (const auto& [a, b] : edges) g.edges.push_back({index[static_cast<size_t>(a)], index[static_cast<size_t>(b)]});
  return g;
}

// A frame's parallel arrays agree (one confidence per element, n × n topologies): the readers
// guarantee it, so a mismatch is a caller's bug, named instead of read past an array's end.
void require_frame_shapes(const std::string& key, const FrameCenterlines& f) {
  const auto square = [](size_t n) { return n * n; };
  const bool lanes_ok = f.confidence.size() == f.lanes.size() && f.topology.size() == square(f.lanes.size());
  const bool map_ok = !f.has_map_elements || (f.segment_confidence.size() == f.segments.size() &&
                                              f.topology_lsls.size() == square(f.segments.size()) &&
                                              f.area_confidence.size() == f.areas.size());
  if (!lanes_ok || !map_ok)
    throw InternalError("score_frames", "frame " + key,
                        "one confidence per lane, lane segment and area and n x n topologies");
}

FramesReport score_frames(const FrameSet& truth_in, const FrameSet& predictions, bool graph_metrics,
                          double max_seconds) {
  for (const auto& [key, f] : predictions) require_frame_shapes(key, f);
  const Budget budget(max_seconds, truth_in.size());
  FramesReport r;
  FrameSet truth;
  for (const auto& [key, f] : truth_in) truth.emplace_back(key, as_float32(f));
  std::map<std::string, const FrameCenterlines*> by_key;
  for (const auto& [key, f] : predictions) by_key[key] = &f;
  static const FrameCenterlines kNothing;
  std::vector<const FrameCenterlines*> preds;
  std::map<std::string, bool> seen;
  for (const auto& [key, f] : truth) {
    const auto it = by_key.find(key);
    if (it == by_key.end()) {
      ++r.missing_frames;
      if (r.missing_examples.size() < 5) r.missing_examples.push_back(key);
    }
    preds.push_back(it == by_key.end() ? &kNothing : it->second);
    seen[key] = true;
    r.gt_centerlines += static_cast<int64_t>(f.lanes.size());
    r.pred_centerlines += static_cast<int64_t>(preds.back()->lanes.size());
  }
  for (const auto& [key, f] : predictions) r.extra_frames += seen.count(key) ? 0 : 1;
  r.frames = static_cast<int64_t>(truth.size());

  std::vector<FrameDetections> detections;
  for (size_t f = 0; f < truth.size(); ++f) {
    budget.check(f);
    const FrameCenterlines& gt = truth[f].second;
    detections.push_back({gt.lanes.size(), preds[f]->confidence, distance_matrix(gt.lanes, preds[f]->lanes),
                          &gt.topology, &preds[f]->topology});
  }
  const LaneScores lanes = lane_scores(detections, budget);
  r.det_l_per_threshold = lanes.det_per_threshold;
  r.det_l = lanes.det;
  r.top_ll = lanes.top;
  r.lane_score = (r.det_l + std::sqrt(r.top_ll)) / 2.0;
  r.has_centerlines =
      std::any_of(predictions.begin(), predictions.end(), [](const auto& p) { return p.second.has_centerlines; }) ||
      predictions.empty();
  const bool truth_has =
      std::all_of(truth.begin(), truth.end(), [](const auto& f) { return f.second.has_map_elements; });
  const bool preds_have =
      std::any_of(predictions.begin(), predictions.end(), [](const auto& p) { return p.second.has_map_elements; });
  if (truth_has && preds_have && !truth.empty()) score_map_elements(truth, preds, budget, r);
  if (graph_metrics) r.graph_means = graph_means(truth, preds, budget);
  return r;
}

nlohmann::ordered_json frames_report_to_json(const FramesReport& r) {
  nlohmann::ordered_json per = nlohmann::ordered_json::object();
  for (size_t t = 0; t < kThresholdsM.size(); ++t)
    per[std::to_string(kThresholdsM[t]).substr(0, 3)] = r.det_l_per_threshold[t];
  nlohmann::ordered_json out = {
      {"schema_version", "1"}, {"frames_metrics_version", kFramesMetricsVersion}, {"split", r.split}};
  const auto or_null = [](bool has, const nlohmann::ordered_json& v) {
    return has ? v : nlohmann::ordered_json(nullptr);
  };
  out["DET_l"] = or_null(r.has_centerlines, r.det_l);
  out["DET_l_per_threshold"] = or_null(r.has_centerlines, per);
  out["TOP_ll"] = or_null(r.has_centerlines, r.top_ll);
  out["lane_score"] = or_null(r.has_centerlines, r.lane_score);
  nlohmann::ordered_json segments = nullptr;
  if (r.has_lane_segments) {
    nlohmann::ordered_json per_ls = nlohmann::ordered_json::object();
    for (size_t t = 0; t < kThresholdsM.size(); ++t)
      per_ls[std::to_string(kThresholdsM[t]).substr(0, 3)] = r.det_ls_per_threshold[t];
    segments = {{"DET_ls", r.det_ls},
                {"DET_ls_per_threshold", per_ls},
                {"DET_a", r.det_a},
                {"DET_a_per_category",
                 {{"pedestrian_crossing", r.det_a_per_category[0]}, {"road_boundary", r.det_a_per_category[1]}}},
                {"TOP_lsls", r.top_lsls},
                {"score", r.ls_score}};
  }
  out["lane_segments"] = segments;
  nlohmann::ordered_json counts = {{"frames", r.frames},
                                   {"missing_frames", r.missing_frames},
                                   {"extra_frames", r.extra_frames},
                                   {"gt_centerlines", r.gt_centerlines},
                                   {"pred_centerlines", r.pred_centerlines}};
  if (r.has_lane_segments) {
    counts["gt_lane_segments"] = r.gt_lane_segments;
    counts["pred_lane_segments"] = r.pred_lane_segments;
    counts["gt_areas"] = r.gt_areas;
    counts["pred_areas"] = r.pred_areas;
  }
  out["counts"] = counts;
  out["nsgraph_metrics"] = r.graph_means.empty() ? nlohmann::ordered_json(nullptr) : graph_json(r);
  out["missing_examples"] = r.missing_examples;
  out["note"] =
      "DET_l and TOP_ll as OpenLane-V2's evaluator computes them; lane_score = (DET_l + sqrt(TOP_ll)) / 2, the lane "
      "terms of OLS, not OLS (no traffic elements). lane_segments: DET_ls, DET_a, TOP_lsls and score as its v2.1 "
      "lanesegment evaluation computes them (score includes its DET_t = 1 and TOP_lt = 0: no traffic elements)";
  return out;
}

}  // namespace nsg::metrics

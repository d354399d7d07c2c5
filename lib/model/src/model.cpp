// Training and prediction of the reference model (model.h); the file format is in
// model_io.cpp, the shared forest helpers in forest.cpp.
#include "nsg/model/model.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

#include <opencv2/core/utility.hpp>

#include "forest.h"
#include "model_impl.h"
#include "nsg/core/error.h"
#include "nsg/core/log.h"
#include "nsg/core/progress.h"
#include "nsg/metrics/io.h"
#include "nsg/model/targets.h"

namespace nsg::model {
namespace {

using detail::draw;
using detail::seconds_since;

constexpr double kTargetRadiusPx = 30.0;              // distances are exact up to here
constexpr double kNearPx = 3.0, kAroundPx = 12.0;     // training strata of the centre head
constexpr double kLanePx = 4.5, kBackgroundPx = 9.0;  // the direction head's lane / background

float soft_target(float distance_px, double sigma_px) {
  return static_cast<float>(std::exp(-0.5 * distance_px * distance_px / (sigma_px * sigma_px)));
}

metrics::Graph truth_of(const io::DatasetTile& tile) { return metrics::tile_graph(tile); }

// Training rows of one tile.
struct TileSamples {
  cv::Mat centre_x, centre_y;  // CV_32F rows, CV_32F likelihood targets
  cv::Mat anchor_y;            // CV_32F anchor targets of the same rows (b2, graph)
  cv::Mat dir_x, dir_y;        // CV_32F rows, CV_32S classes
};

TileSamples sample_tile(const io::DatasetTile& tile, const ModelOptions& o) {
  const TileInput input = tile_input_from_dataset(tile);
  const FeatureMaps f = compute_features(input, o.modalities);
  const metrics::Graph truth = truth_of(tile);
  const TileTargets t = compute_targets(truth, input.size_px(), kTargetRadiusPx);

  std::vector<int> near, around, far, lane, background;
  const int size = input.size_px();
  for (int i = 0; i < size * size; ++i) {
    if (!f.support.data[i]) continue;
    const float d = reinterpret_cast<const float*>(t.distance_px.data)[i];
    (d <= kNearPx ? near : d <= kAroundPx ? around : far).push_back(i);
    if (d <= kLanePx) lane.push_back(i);
    else if (d > kBackgroundPx) background.push_back(i);
  }
  Rng rng(o.seed, detail::key_stream(tile.key));
  TileSamples s;
  const bool anchors = o.variant != Variant::kB1;
  for (const auto& [pool, k] : {std::pair{&near, o.centre_samples_near}, std::pair{&around, o.centre_samples_around},
                                std::pair{&far, o.centre_samples_far}}) {
    const std::vector<int> rows = draw(*pool, k, rng);
    for (int r : rows) {
      s.centre_x.push_back(f.values.row(r));
      s.centre_y.push_back(soft_target(reinterpret_cast<const float*>(t.distance_px.data)[r], o.sigma_px));
      // The anchor head learns from the centre head's rows: no extra draws, so b1's
      // samples are the same whatever the variant.
      if (anchors) s.anchor_y.push_back(anchor_target(truth, r % size, r / size, o.anchors.target_sigma_px));
    }
  }
  for (int r : draw(lane, o.direction_samples_lane, rng)) {
    s.dir_x.push_back(f.values.row(r));
    s.dir_y.push_back(direction_bin(reinterpret_cast<const float*>(t.angle_rad.data)[r]));
  }
  for (int r : draw(background, o.direction_samples_background, rng)) {
    s.dir_x.push_back(f.values.row(r));
    s.dir_y.push_back(kBackgroundClass);
  }
  return s;
}

// Caps every direction class at three times the mean class count (deterministic draw), so
// the few diagonal bins are not drowned by the axis-aligned ones.
void balance_classes(cv::Mat& x, cv::Mat& y, uint64_t seed) {
  std::vector<std::vector<int>> by_class(kDirectionClasses);
  for (int r = 0; r < y.rows; ++r) by_class[static_cast<size_t>(y.at<int>(r))].push_back(r);
  size_t non_empty = 0, total = 0;
  for (const auto& c : by_class) {
    non_empty += c.empty() ? 0 : 1;
    total += c.size();
  }
  if (non_empty == 0) return;
  const int cap = static_cast<int>(3 * total / non_empty);
  Rng rng(seed, 0xba1a);
  std::vector<int> keep;
  for (const auto& c : by_class) {
    std::vector<int> rows = draw(c, cap, rng);
    keep.insert(keep.end(), rows.begin(), rows.end());
  }
  std::sort(keep.begin(), keep.end());
  cv::Mat nx, ny;
  for (int r : keep) {
    nx.push_back(x.row(r));
    ny.push_back(y.row(r));
  }
  x = nx;
  y = ny;
}

// Accuracy of a classifier on the rows whose label is not `ignored` (the direction head's
// background, whose job is the graph's); NaN without such rows.
double accuracy(const cv::ml::RTrees& rt, const cv::Mat& x, const cv::Mat& y, int ignored) {
  if (x.rows == 0) return std::nan("");
  cv::Mat pred;
  rt.predict(x, pred);
  int counted = 0, right = 0;
  for (int r = 0; r < x.rows; ++r) {
    if (y.at<int>(r) == ignored) continue;
    ++counted;
    right += static_cast<int>(std::lround(pred.at<float>(r))) == y.at<int>(r);
  }
  return counted ? static_cast<double>(right) / counted : std::nan("");
}

bool is_holdout(const ModelOptions& o, size_t i) {
  return o.holdout_every > 0 && i % static_cast<size_t>(o.holdout_every) == static_cast<size_t>(o.holdout_every - 1);
}

// What the forests say about one tile.
struct TileMaps {
  FeatureMaps features;
  cv::Mat likelihood, anchor_score;
};

TileMaps tile_maps(const LaneModel::Impl& m, const TileInput& tile) {
  TileMaps t;
  t.features = compute_features(tile, m.options.modalities);
  t.likelihood = detail::forest_map(*m.centre, t.features, tile.size_px(), m.options.predict_stride_px);
  if (m.anchor) t.anchor_score = detail::forest_map(*m.anchor, t.features, tile.size_px(), m.options.predict_stride_px);
  return t;
}

DirectionVotes votes_of(const LaneModel::Impl& m, const TileMaps& t, int size) {
  return [&m, &t, size](const std::vector<std::array<double, 2>>& anchors) {
    return detail::window_votes(*m.direction, t.features, size, anchors);
  };
}

// The connection classifier's training pairs: the trained heads predict anchors on every
// k-th training tile; candidate pairs get labels from the adaptive ground truth.
struct PairSamples {
  cv::Mat x, y;  // CV_32F rows, CV_32S labels 0 / 1
};

PairSamples pair_samples(const LaneModel::Impl& m, const io::DatasetTile& tile) {
  const TileInput input = tile_input_from_dataset(tile);
  const TileMaps t = tile_maps(m, input);
  const AnchorSet a = make_anchor_set(t.anchor_score, votes_of(m, t, input.size_px()), m.options.anchors);
  const std::vector<std::array<int, 2>> pairs = candidate_pairs(a.points, m.options.pairs.radius_px);
  PairSamples s;
  if (pairs.empty()) return s;
  s.x = pair_features(a, pairs, t.likelihood, t.anchor_score);
  for (int label : connection_labels(truth_of(tile), a.points, pairs, m.options.pairs)) s.y.push_back(label);
  return s;
}

void train_connection(LaneModel::Impl& m, const io::Dataset& dataset, const std::string& split, ThreadPool& pool,
                      size_t total, bool progress, TrainReport& r) {
  const auto t0 = std::chrono::steady_clock::now();
  // A small split gives pairs from more of its tiles: at least ≈ 30 tiles when it has them.
  const size_t every = std::max<size_t>(1, std::min(static_cast<size_t>(m.options.pairs.train_tile_every), total / 30));
  // Every k-th tile, plus every other held-out tile for the held-out accuracy (the k-th
  // tiles may never be held out, e.g. k = 4 with every 10th held out).
  auto wanted = [&](size_t i) {
    return i % every == 0 || (is_holdout(m.options, i) && (i / static_cast<size_t>(m.options.holdout_every)) % 2 == 0);
  };
  std::vector<PairSamples> slots(total);
  {
    Progress bar("pairs " + split, total, progress);
    detail::for_each_tile_parallel(dataset, split, pool, [&](size_t i, const io::DatasetTile& tile) {
      if (i < total && wanted(i)) slots[i] = pair_samples(m, tile);
      bar.advance();
    });
  }
  cv::Mat x, y, hx, hy;
  for (size_t i = 0; i < total; ++i) {
    if (slots[i].x.empty()) continue;
    (is_holdout(m.options, i) ? hx : x).push_back(slots[i].x);
    (is_holdout(m.options, i) ? hy : y).push_back(slots[i].y);
  }
  NSG_CHECK(x.rows > 0, DataError, (dataset.root() / "manifest.json").string(), "split " + split,
            "anchor pairs to train the connection classifier on (no anchors found on the training tiles)");
  m.connection = detail::train_forest(m.options.connection, x, y, true, mix64(m.options.seed ^ 0xc011ec7ull));
  r.pair_samples = static_cast<size_t>(x.rows);
  r.pair_positives = static_cast<size_t>(cv::countNonZero(y));
  r.pair_accuracy_train = accuracy(*m.connection, x, y, -1);
  r.pair_accuracy_holdout = accuracy(*m.connection, hx, hy, -1);
  r.pairs_s = seconds_since(t0);
  log::info("connection classifier: " + std::to_string(r.pair_samples) + " pairs (" + std::to_string(r.pair_positives) +
            " connected) from every " + std::to_string(every) + ". tile");
}

// Every tile's training rows, in split order, sampled in parallel.
std::vector<TileSamples> sample_split(const io::Dataset& dataset, const std::string& split, const ModelOptions& options,
                                      ThreadPool& pool, size_t total, bool progress) {
  std::vector<TileSamples> slots(total);
  Progress bar("features " + split, total, progress);
  detail::for_each_tile_parallel(dataset, split, pool, [&](size_t i, const io::DatasetTile& tile) {
    NSG_CHECK(i < total, DataError, (dataset.root() / "manifest.json").string(), "split " + split,
              "tile counts that match the shards");
    slots[i] = sample_tile(tile, options);
    bar.advance();
  });
  return slots;
}

// The pixel heads' training rows and, prefixed h, the held-out tiles' rows.
struct PixelSamples {
  cv::Mat cx, cy, ay, dx, dy, hcx, hcy, hay, hdx, hdy;
};

// Stacks the tiles' rows in tile order into training or held-out rows, freeing each tile's
// as it goes; counts the tiles of each in `r`.
PixelSamples stack_samples(std::vector<TileSamples>& slots, const ModelOptions& options, TrainReport& r) {
  PixelSamples p;
  for (size_t i = 0; i < slots.size(); ++i) {
    const bool holdout = is_holdout(options, i);
    TileSamples& s = slots[i];
    (holdout ? p.hcx : p.cx).push_back(s.centre_x);
    (holdout ? p.hcy : p.cy).push_back(s.centre_y);
    (holdout ? p.hay : p.ay).push_back(s.anchor_y);
    (holdout ? p.hdx : p.dx).push_back(s.dir_x);
    (holdout ? p.hdy : p.dy).push_back(s.dir_y);
    s = TileSamples{};
    ++(holdout ? r.holdout_tiles : r.tiles);
  }
  return p;
}

// The forests are independent: the direction head, then the anchor head, beside the
// centreline head when there is a second core (the centreline forest has the most
// samples). Each is seeded on its own thread, so the bytes do not depend on this.
void train_pixel_heads(LaneModel::Impl& m, const ModelOptions& options, const PixelSamples& s, bool second_core) {
  std::thread second;
  auto train_others = [&] {
    m.direction = detail::train_forest(options.direction, s.dx, s.dy, true, options.seed * 2 + 1);
    if (options.variant != Variant::kB1) {
      m.anchor = detail::train_forest(options.anchor, s.cx, s.ay, false, mix64(options.seed ^ 0xa4c402ull));
    }
  };
  if (second_core) second = std::thread(train_others);
  m.centre = detail::train_forest(options.centre, s.cx, s.cy, false, options.seed * 2);
  if (second.joinable()) second.join();
  else train_others();
}

// The pixel heads' errors on the training and held-out rows, into `r` and the model's report.
void measure_pixel_heads(LaneModel::Impl& m, const std::string& split, const PixelSamples& s, TrainReport& r) {
  r.centre_mse_train = detail::mse(*m.centre, s.cx, s.cy);
  r.centre_mse_holdout = detail::mse(*m.centre, s.hcx, s.hcy);
  r.direction_accuracy_train = accuracy(*m.direction, s.dx, s.dy, kBackgroundClass);
  r.direction_accuracy_holdout = accuracy(*m.direction, s.hdx, s.hdy, kBackgroundClass);
  m.report = {{"split", split},
              {"tiles", r.tiles},
              {"holdout_tiles", r.holdout_tiles},
              {"centre_samples", r.centre_samples},
              {"direction_samples", r.direction_samples},
              {"centre_mse_train", r.centre_mse_train},
              {"centre_mse_holdout", r.centre_mse_holdout},
              {"direction_accuracy_train", r.direction_accuracy_train},
              {"direction_accuracy_holdout", r.direction_accuracy_holdout}};
  if (m.anchor) {
    r.anchor_mse_train = detail::mse(*m.anchor, s.cx, s.ay);
    r.anchor_mse_holdout = detail::mse(*m.anchor, s.hcx, s.hay);
    m.report["anchor_mse_train"] = r.anchor_mse_train;
    m.report["anchor_mse_holdout"] = r.anchor_mse_holdout;
  }
}

}  // namespace

LaneModel::LaneModel() : impl_(std::make_unique<Impl>()) {}
LaneModel::~LaneModel() = default;
LaneModel::LaneModel(LaneModel&&) noexcept = default;
LaneModel& LaneModel::operator=(LaneModel&&) noexcept = default;
const ModelOptions& LaneModel::options() const { return impl_->options; }

LaneModel LaneModel::train(const io::Dataset& dataset, const std::string& split, const ModelOptions& options,
                           int threads, bool progress, TrainReport* report) {
  options.validate();
  cv::setNumThreads(1);  // our own pool parallelizes over tiles; results never depend on it
  const auto t0 = std::chrono::steady_clock::now();
  ThreadPool pool(resolve_threads(threads));
  dataset.require_split(split);  // a mistyped split is named with the ones there are
  const size_t total = detail::split_tile_count(dataset, split);
  NSG_CHECK(total > 0, DataError, (dataset.root() / "manifest.json").string(), "split " + split,
            "at least one tile to train on");
  std::vector<TileSamples> slots = sample_split(dataset, split, options, pool, total, progress);
  TrainReport r;
  PixelSamples s = stack_samples(slots, options, r);
  balance_classes(s.dx, s.dy, options.seed);
  r.centre_samples = static_cast<size_t>(s.cx.rows);
  r.direction_samples = static_cast<size_t>(s.dx.rows);
  r.features_s = seconds_since(t0);
  log::info("training " + to_string(options.variant) + " on " + std::to_string(r.tiles) + " tiles (" +
            std::to_string(r.holdout_tiles) + " held out): " + std::to_string(s.cx.rows) + " centreline and " +
            std::to_string(s.dx.rows) + " direction samples, " + std::to_string(s.cx.cols) + " features");

  const auto t1 = std::chrono::steady_clock::now();
  LaneModel model;
  Impl& m = *model.impl_;
  m.options = options;
  m.feature_names = feature_names(options.modalities);
  train_pixel_heads(m, options, s, pool.size() > 1);
  r.train_s = seconds_since(t1);
  measure_pixel_heads(m, split, s, r);
  if (options.variant == Variant::kGraph) {
    s.cx = s.cy = s.ay = s.dx = s.dy = cv::Mat();  // the pixel samples are done with; free them
    train_connection(m, dataset, split, pool, total, progress, r);
    m.report["pair_samples"] = r.pair_samples;
    m.report["pair_positives"] = r.pair_positives;
    m.report["pair_accuracy_train"] = r.pair_accuracy_train;
    m.report["pair_accuracy_holdout"] = r.pair_accuracy_holdout;
  }
  if (report) *report = r;
  return model;
}

TilePrediction LaneModel::predict(const TileInput& tile) const {
  const Impl& m = *impl_;
  const TileMaps t = tile_maps(m, tile);
  const DirectionVotes votes = votes_of(m, t, tile.size_px());
  TilePrediction p;
  p.likelihood = t.likelihood;
  p.anchor_score = t.anchor_score;
  switch (m.options.variant) {
    case Variant::kB1: p.graph = extract_graph(p.likelihood, votes, m.options.extraction); break;
    case Variant::kB2:
      p.graph = b2_graph(make_anchor_set(t.anchor_score, votes, m.options.anchors), t.likelihood, m.options.anchors,
                         m.options.extraction);
      break;
    case Variant::kGraph: {
      const PairScorer scorer = [&m](const cv::Mat& x) { return detail::positive_fraction(*m.connection, x); };
      p.graph = pair_graph(make_anchor_set(t.anchor_score, votes, m.options.anchors), t.likelihood, t.anchor_score,
                           m.options.pairs, scorer, m.options.extraction);
      break;
    }
  }
  return p;
}

metrics::GraphSet predict_dataset(const LaneModel& model, const io::Dataset& dataset, const std::string& split,
                                  int threads, bool progress) {
  cv::setNumThreads(1);
  ThreadPool pool(resolve_threads(threads));
  return detail::predict_split(dataset, split, pool, progress,
                               [&](const TileInput& input) { return model.predict(input).graph; });
}

}  // namespace nsg::model

#include "nsg/model/model.h"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <thread>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/ml.hpp>

#include "gzip.h"
#include "nsg/core/atomic_file.h"
#include "nsg/core/error.h"
#include "nsg/core/log.h"
#include "nsg/core/parallel.h"
#include "nsg/core/progress.h"
#include "nsg/core/rng.h"
#include "nsg/core/version.h"
#include "nsg/metrics/io.h"
#include "nsg/model/targets.h"

namespace nsg::model {
namespace {

constexpr const char* kFormat = "nsgraph-lane-model";
constexpr int kFormatVersion = 1;
constexpr double kTargetRadiusPx = 30.0;     // distances are exact up to here
constexpr double kNearPx = 3.0, kAroundPx = 12.0;  // training strata of the centre head
constexpr double kLanePx = 4.5, kBackgroundPx = 9.0;  // the direction head's lane / background

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// FNV-1a of a tile key: the tile's own random stream, independent of visiting order.
uint64_t key_stream(const std::string& key) {
  uint64_t h = 1469598103934665603ull;
  for (unsigned char c : key) h = (h ^ c) * 1099511628211ull;
  return h;
}

// Up to k indices drawn without replacement (partial Fisher–Yates), in drawn order.
std::vector<int> draw(std::vector<int> pool, int k, Rng& rng) {
  const size_t take = std::min(pool.size(), static_cast<size_t>(std::max(k, 0)));
  for (size_t i = 0; i < take; ++i) {
    const size_t j = i + static_cast<size_t>(rng.uniform_int(pool.size() - i));
    std::swap(pool[i], pool[j]);
  }
  pool.resize(take);
  return pool;
}

float soft_target(float distance_px, double sigma_px) {
  return static_cast<float>(std::exp(-0.5 * distance_px * distance_px / (sigma_px * sigma_px)));
}

// Training rows of one tile.
struct TileSamples {
  cv::Mat centre_x, centre_y;  // CV_32F rows, CV_32F likelihood targets
  cv::Mat dir_x, dir_y;        // CV_32F rows, CV_32S classes
};

void append_rows(const cv::Mat& values, const std::vector<int>& rows, cv::Mat& out) {
  for (int r : rows) out.push_back(values.row(r));
}

TileSamples sample_tile(const io::DatasetTile& tile, const ModelOptions& o) {
  const TileInput input = tile_input_from_dataset(tile);
  const FeatureMaps f = compute_features(input, o.modalities);
  const auto graph_bytes = tile.files.find("graph.json");
  NSG_CHECK(graph_bytes != tile.files.end(), ParseError, tile.key + ".graph.json", "file", "the tile's graph");
  const metrics::Graph truth = metrics::graph_from_dataset_json(
      std::string(graph_bytes->second.begin(), graph_bytes->second.end()), tile.key + ".graph.json");
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
  Rng rng(o.seed, key_stream(tile.key));
  TileSamples s;
  for (const auto& [pool, k] : {std::pair{&near, o.centre_samples_near}, std::pair{&around, o.centre_samples_around},
                                std::pair{&far, o.centre_samples_far}}) {
    const std::vector<int> rows = draw(*pool, k, rng);
    append_rows(f.values, rows, s.centre_x);
    for (int r : rows) s.centre_y.push_back(soft_target(reinterpret_cast<const float*>(t.distance_px.data)[r], o.sigma_px));
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

// The centreline forest on every stride-th supported pixel, interpolated bilinearly to
// the full grid (0 where no supported sample is near).
cv::Mat centre_likelihood(const cv::ml::RTrees& forest, const FeatureMaps& f, int size, int stride) {
  const int coarse = (size + stride - 1) / stride;
  std::vector<int> rows, cells;
  for (int cv_ = 0; cv_ < coarse; ++cv_) {
    for (int cu = 0; cu < coarse; ++cu) {
      const int i = (cv_ * stride) * size + cu * stride;
      if (!f.support.data[i]) continue;
      rows.push_back(i);
      cells.push_back(cv_ * coarse + cu);
    }
  }
  cv::Mat grid = cv::Mat::zeros(coarse, coarse, CV_32F);
  if (!rows.empty()) {
    cv::Mat x(static_cast<int>(rows.size()), f.values.cols, CV_32F), out;
    for (size_t k = 0; k < rows.size(); ++k) f.values.row(rows[k]).copyTo(x.row(static_cast<int>(k)));
    forest.predict(x, out);
    for (size_t k = 0; k < rows.size(); ++k) {
      reinterpret_cast<float*>(grid.data)[cells[k]] = std::clamp(out.at<float>(static_cast<int>(k)), 0.0f, 1.0f);
    }
  }
  if (stride == 1) return grid;
  // Fine pixel (u, v) lies at coarse (u / stride, v / stride).
  cv::Mat mu(size, size, CV_32F), mv(size, size, CV_32F), fine;
  for (int v = 0; v < size; ++v) {
    for (int u = 0; u < size; ++u) {
      mu.at<float>(v, u) = static_cast<float>(u) / stride;
      mv.at<float>(v, u) = static_cast<float>(v) / stride;
    }
  }
  cv::remap(grid, fine, mu, mv, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  return fine;
}

// LaneDirNet's votes summed over the (2r+1)² pixels around each anchor, in one batch.
std::vector<Votes> window_votes(const cv::ml::RTrees& forest, const FeatureMaps& f, int size,
                                const std::vector<std::array<double, 2>>& anchors) {
  constexpr int kRadiusPx = 1;
  constexpr int kWindow = (2 * kRadiusPx + 1) * (2 * kRadiusPx + 1);
  cv::Mat x(static_cast<int>(anchors.size()) * kWindow, f.values.cols, CV_32F);
  int row = 0;
  for (const auto& a : anchors) {
    const int u0 = static_cast<int>(std::lround(a[0])), v0 = static_cast<int>(std::lround(a[1]));
    for (int dv = -kRadiusPx; dv <= kRadiusPx; ++dv) {
      for (int du = -kRadiusPx; du <= kRadiusPx; ++du) {
        const int u = std::clamp(u0 + du, 0, size - 1), v = std::clamp(v0 + dv, 0, size - 1);
        f.values.row(v * size + u).copyTo(x.row(row++));
      }
    }
  }
  cv::Mat raw;
  forest.getVotes(x, raw, 0);
  // Row 0 holds the class label of each column; row 1 + r the votes of sample r.
  std::vector<Votes> out(anchors.size(), Votes{});
  for (int r = 0; r < x.rows; ++r) {
    Votes& v = out[static_cast<size_t>(r / kWindow)];
    for (int c = 0; c < raw.cols; ++c) {
      const int label = raw.at<int>(0, c);
      if (label >= 0 && label < kDirectionClasses) v[static_cast<size_t>(label)] += static_cast<float>(raw.at<int>(r + 1, c));
    }
  }
  return out;
}

cv::Ptr<cv::ml::RTrees> make_forest(const ForestOptions& f) {
  cv::Ptr<cv::ml::RTrees> rt = cv::ml::RTrees::create();
  rt->setMaxDepth(f.max_depth);
  rt->setMinSampleCount(f.min_samples);
  rt->setRegressionAccuracy(0.0f);
  rt->setUseSurrogates(false);
  rt->setCVFolds(0);
  rt->setCalculateVarImportance(false);
  rt->setActiveVarCount(0);  // √features per split
  rt->setTermCriteria(cv::TermCriteria(cv::TermCriteria::MAX_ITER, f.trees, 0.0));
  return rt;
}

cv::Ptr<cv::ml::RTrees> train_forest(const ForestOptions& f, const cv::Mat& x, const cv::Mat& y, bool classifier,
                                     uint64_t seed) {
  NSG_CHECK(x.rows > 0, DataError, "", "training samples", "at least one sample (no tile with data in the split?)");
  cv::Mat var_type(1, x.cols + 1, CV_8U, cv::Scalar(cv::ml::VAR_ORDERED));
  if (classifier) var_type.at<uint8_t>(x.cols) = cv::ml::VAR_CATEGORICAL;
  const cv::Ptr<cv::ml::TrainData> data = cv::ml::TrainData::create(x, cv::ml::ROW_SAMPLE, y, cv::noArray(),
                                                                    cv::noArray(), cv::noArray(), var_type);
  cv::Ptr<cv::ml::RTrees> rt = make_forest(f);
  // OpenCV's bagging draws from the calling thread's cv::theRNG(): seed it here, on the
  // training thread, so a forest never depends on which thread trains it or on what ran before.
  cv::theRNG() = cv::RNG(seed);
  rt->train(data);
  return rt;
}

double mse(const cv::ml::RTrees& rt, const cv::Mat& x, const cv::Mat& y) {
  if (x.rows == 0) return std::nan("");
  cv::Mat pred;
  rt.predict(x, pred);
  const cv::Mat diff = pred - y;
  return diff.dot(diff) / x.rows;
}

// Accuracy on lane samples (background rows excluded: the heads' job there is the graph's).
double lane_accuracy(const cv::ml::RTrees& rt, const cv::Mat& x, const cv::Mat& y) {
  cv::Mat pred;
  if (x.rows == 0) return std::nan("");
  rt.predict(x, pred);
  int lane = 0, right = 0;
  for (int r = 0; r < x.rows; ++r) {
    if (y.at<int>(r) == kBackgroundClass) continue;
    ++lane;
    right += static_cast<int>(std::lround(pred.at<float>(r))) == y.at<int>(r);
  }
  return lane ? static_cast<double>(right) / lane : std::nan("");
}

size_t split_tile_count(const io::Dataset& dataset, const std::string& split) {
  size_t n = 0;
  for (const auto& s : dataset.shards(split)) n += s.value("tiles", 0);
  return n;
}

// Runs fn(tile index, tile) for every tile of the split: shard by shard, tiles of a shard
// in parallel (results must go to per-index slots).
void for_each_tile_parallel(const io::Dataset& dataset, const std::string& split, ThreadPool& pool,
                            const std::function<void(size_t, const io::DatasetTile&)>& fn) {
  size_t base = 0;
  for (const auto& shard : dataset.shards(split)) {
    const std::vector<io::DatasetTile> tiles = dataset.read_shard(shard);
    pool.parallel_for(tiles.size(), [&](size_t i) { fn(base + i, tiles[i]); });
    base += tiles.size();
  }
}

// A stored number, or `fallback` when the field is absent (files from before it existed).
template <typename T>
T value_or(const cv::FileNode& n, T fallback) {
  return n.empty() ? fallback : static_cast<T>(static_cast<double>(n));
}

void write_forest_options(cv::FileStorage& fs, const std::string& name, const ForestOptions& f) {
  fs << name << "{" << "trees" << f.trees << "max_depth" << f.max_depth << "min_samples" << f.min_samples << "}";
}

ForestOptions read_forest_options(const cv::FileNode& n) {
  return ForestOptions{static_cast<int>(n["trees"]), static_cast<int>(n["max_depth"]),
                       static_cast<int>(n["min_samples"])};
}

}  // namespace

void ForestOptions::validate(const std::string& field) const {
  NSG_CHECK(trees >= 1 && trees <= 1000, ConfigError, "", field + ".trees", "1 … 1000");
  NSG_CHECK(max_depth >= 1 && max_depth <= 40, ConfigError, "", field + ".max_depth", "1 … 40");
  NSG_CHECK(min_samples >= 1, ConfigError, "", field + ".min_samples", "≥ 1");
}

void ModelOptions::validate() const {
  modalities.validate();
  centre.validate("centre");
  direction.validate("direction");
  NSG_CHECK(sigma_px > 0.0 && sigma_px < 20.0, ConfigError, "", "sigma_px", "in (0, 20) px");
  for (int k : {centre_samples_near, centre_samples_around, centre_samples_far, direction_samples_lane,
                direction_samples_background}) {
    NSG_CHECK(k >= 0 && k <= 100000, ConfigError, "", "samples per tile", "0 … 100000");
  }
  NSG_CHECK(predict_stride_px >= 1 && predict_stride_px <= 4, ConfigError, "", "predict_stride_px", "1 … 4");
  NSG_CHECK(holdout_every == 0 || holdout_every >= 2, ConfigError, "", "holdout_every", "0 (none) or ≥ 2");
  extraction.validate();
}

struct LaneModel::Impl {
  ModelOptions options;
  std::vector<std::string> feature_names;
  cv::Ptr<cv::ml::RTrees> centre, direction;
  nlohmann::json report;  // what training measured, kept in the file for provenance
};

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
  const size_t total = split_tile_count(dataset, split);
  NSG_CHECK(total > 0, DataError, (dataset.root() / "manifest.json").string(), "split " + split,
            "at least one tile to train on");
  std::vector<TileSamples> slots(total);
  {
    Progress bar("features " + split, total, progress);
    for_each_tile_parallel(dataset, split, pool, [&](size_t i, const io::DatasetTile& tile) {
      NSG_CHECK(i < total, DataError, (dataset.root() / "manifest.json").string(), "split " + split,
                "tile counts that match the shards");
      slots[i] = sample_tile(tile, options);
      bar.advance();
    });
  }
  cv::Mat cx, cy, dx, dy, hcx, hcy, hdx, hdy;
  TrainReport r;
  for (size_t i = 0; i < total; ++i) {
    const bool holdout = options.holdout_every > 0 && i % static_cast<size_t>(options.holdout_every) ==
                                                          static_cast<size_t>(options.holdout_every - 1);
    TileSamples& s = slots[i];
    (holdout ? hcx : cx).push_back(s.centre_x);
    (holdout ? hcy : cy).push_back(s.centre_y);
    (holdout ? hdx : dx).push_back(s.dir_x);
    (holdout ? hdy : dy).push_back(s.dir_y);
    s = TileSamples{};
    ++(holdout ? r.holdout_tiles : r.tiles);
  }
  balance_classes(dx, dy, options.seed);
  r.centre_samples = static_cast<size_t>(cx.rows);
  r.direction_samples = static_cast<size_t>(dx.rows);
  r.features_s = seconds_since(t0);
  log::info("training on " + std::to_string(r.tiles) + " tiles (" + std::to_string(r.holdout_tiles) +
           " held out): " + std::to_string(cx.rows) + " centreline and " + std::to_string(dx.rows) +
           " direction samples, " + std::to_string(cx.cols) + " features");

  const auto t1 = std::chrono::steady_clock::now();
  LaneModel model;
  model.impl_->options = options;
  model.impl_->feature_names = feature_names(options.modalities);
  // The two forests are independent: train them side by side when there is a second core.
  std::thread direction_thread;
  auto train_direction = [&] {
    model.impl_->direction = train_forest(options.direction, dx, dy, true, options.seed * 2 + 1);
  };
  if (pool.size() > 1) direction_thread = std::thread(train_direction);
  model.impl_->centre = train_forest(options.centre, cx, cy, false, options.seed * 2);
  if (direction_thread.joinable()) direction_thread.join();
  else train_direction();
  r.train_s = seconds_since(t1);

  r.centre_mse_train = mse(*model.impl_->centre, cx, cy);
  r.centre_mse_holdout = mse(*model.impl_->centre, hcx, hcy);
  r.direction_accuracy_train = lane_accuracy(*model.impl_->direction, dx, dy);
  r.direction_accuracy_holdout = lane_accuracy(*model.impl_->direction, hdx, hdy);
  model.impl_->report = {{"split", split},
                         {"tiles", r.tiles},
                         {"holdout_tiles", r.holdout_tiles},
                         {"centre_samples", r.centre_samples},
                         {"direction_samples", r.direction_samples},
                         {"centre_mse_train", r.centre_mse_train},
                         {"centre_mse_holdout", r.centre_mse_holdout},
                         {"direction_accuracy_train", r.direction_accuracy_train},
                         {"direction_accuracy_holdout", r.direction_accuracy_holdout}};
  if (report) *report = r;
  return model;
}

void LaneModel::save(const std::filesystem::path& path) const {
  const Impl& m = *impl_;
  cv::FileStorage fs(".yml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
  fs << "format" << kFormat << "format_version" << kFormatVersion << "tool_version" << kVersion;
  fs << "modalities" << m.options.modalities.to_string();
  fs << "features" << "[";
  for (const auto& n : m.feature_names) fs << n;
  fs << "]";
  fs << "predict_stride_px" << m.options.predict_stride_px;
  // The seed as text: FileStorage numbers are int or double, too narrow for every uint64.
  fs << "sigma_px" << m.options.sigma_px << "seed" << std::to_string(m.options.seed);
  write_forest_options(fs, "centre_forest", m.options.centre);
  write_forest_options(fs, "direction_forest", m.options.direction);
  const ExtractionOptions& e = m.options.extraction;
  fs << "extraction" << "{" << "threshold" << e.threshold << "min_component_px" << e.min_component_px
     << "min_spur_px" << e.min_spur_px << "simplify_tolerance_px" << e.simplify_tolerance_px
     << "anchor_spacing_px" << e.anchor_spacing_px << "min_node_score" << e.min_node_score
     << "min_edge_score" << e.min_edge_score << "max_edge_fraction" << e.max_edge_fraction
     << "smooth_sigma_px" << e.smooth_sigma_px << "min_piece_length_px" << e.min_piece_length_px
     << "max_direction_angle_deg" << e.max_direction_angle_deg << "}";
  // Numbers in the map (OpenCV's YAML writer mangles strings that look like JSON); the
  // split's name, a plain word, beside it.
  fs << "training_report" << "{";
  for (const auto& [k, v] : m.report.items()) {
    if (v.is_number()) fs << k << v.get<double>();
  }
  fs << "}";
  if (m.report.contains("split") && m.report["split"].is_string())
    fs << "training_split" << m.report["split"].get<std::string>();
  fs << "centre" << "{";
  m.centre->write(fs);
  fs << "}";
  fs << "direction" << "{";
  m.direction->write(fs);
  fs << "}";
  const std::string text = fs.releaseAndGetString();
  const bool gz = path.extension() == ".gz";
  write_file_atomic(path, gz ? gzip_compress(text) : text);
}

LaneModel LaneModel::load(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::string text = read_maybe_gzip(path);
  LaneModel model;
  Impl& m = *model.impl_;
  try {
    cv::FileStorage fs(text, cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
    NSG_CHECK(fs.isOpened() && static_cast<std::string>(fs["format"]) == kFormat, ParseError, file, "format",
              std::string("an nsgraph model (format: ") + kFormat + ")");
    NSG_CHECK(static_cast<int>(fs["format_version"]) == kFormatVersion, ParseError, file, "format_version",
              "version " + std::to_string(kFormatVersion));
    m.options.modalities = Modalities::parse(static_cast<std::string>(fs["modalities"]));
    for (const auto& n : fs["features"]) m.feature_names.push_back(static_cast<std::string>(n));
    NSG_CHECK(m.feature_names == feature_names(m.options.modalities), ParseError, file, "features",
              "the feature list of this nsgraph version for modalities " + m.options.modalities.to_string() +
                  " (retrain the model)");
    m.options.sigma_px = static_cast<double>(fs["sigma_px"]);
    m.options.predict_stride_px = static_cast<int>(fs["predict_stride_px"]);
    const std::string seed = static_cast<std::string>(fs["seed"]);
    const auto [end, ec] = std::from_chars(seed.data(), seed.data() + seed.size(), m.options.seed);
    NSG_CHECK(ec == std::errc() && end == seed.data() + seed.size() && !seed.empty(), ParseError, file, "seed",
              "an unsigned integer as text");
    m.options.centre = read_forest_options(fs["centre_forest"]);
    m.options.direction = read_forest_options(fs["direction_forest"]);
    const cv::FileNode e = fs["extraction"];
    ExtractionOptions& x = m.options.extraction;
    x.threshold = value_or(e["threshold"], x.threshold);
    x.min_component_px = value_or(e["min_component_px"], x.min_component_px);
    x.min_spur_px = value_or(e["min_spur_px"], x.min_spur_px);
    x.simplify_tolerance_px = value_or(e["simplify_tolerance_px"], x.simplify_tolerance_px);
    x.anchor_spacing_px = value_or(e["anchor_spacing_px"], x.anchor_spacing_px);
    x.min_node_score = value_or(e["min_node_score"], x.min_node_score);
    x.min_edge_score = value_or(e["min_edge_score"], x.min_edge_score);
    x.max_edge_fraction = value_or(e["max_edge_fraction"], x.max_edge_fraction);
    x.smooth_sigma_px = value_or(e["smooth_sigma_px"], x.smooth_sigma_px);
    x.min_piece_length_px = value_or(e["min_piece_length_px"], x.min_piece_length_px);
    x.max_direction_angle_deg = value_or(e["max_direction_angle_deg"], x.max_direction_angle_deg);
    m.report = nlohmann::json::object();
    for (const auto& n : fs["training_report"]) m.report[n.name()] = static_cast<double>(n);
    if (fs["training_split"].isString()) m.report["split"] = static_cast<std::string>(fs["training_split"]);
    m.centre = cv::ml::RTrees::create();
    m.centre->read(fs["centre"]);
    m.direction = cv::ml::RTrees::create();
    m.direction->read(fs["direction"]);
    NSG_CHECK(m.centre->isTrained() && m.direction->isTrained(), ParseError, file, "centre/direction",
              "two trained forests");
  } catch (const cv::Exception& ex) {
    throw ParseError(file, "model", std::string("a readable OpenCV FileStorage (") + ex.what() + ")");
  }
  m.options.validate();
  return model;
}

TilePrediction LaneModel::predict(const TileInput& tile) const {
  const Impl& m = *impl_;
  const FeatureMaps f = compute_features(tile, m.options.modalities);
  const int size = tile.size_px();
  TilePrediction p;
  p.likelihood = centre_likelihood(*m.centre, f, tile.size_px(), m.options.predict_stride_px);
  const DirectionVotes votes = [&](const std::vector<std::array<double, 2>>& anchors) {
    return window_votes(*m.direction, f, size, anchors);
  };
  p.graph = extract_graph(p.likelihood, votes, m.options.extraction);
  return p;
}

metrics::GraphSet predict_dataset(const LaneModel& model, const io::Dataset& dataset, const std::string& split,
                                  int threads, bool progress) {
  cv::setNumThreads(1);
  ThreadPool pool(resolve_threads(threads));
  const size_t total = split_tile_count(dataset, split);
  std::vector<std::pair<std::string, metrics::Graph>> slots(total);
  Progress bar("predict " + split, total, progress);
  for_each_tile_parallel(dataset, split, pool, [&](size_t i, const io::DatasetTile& tile) {
    NSG_CHECK(i < total, DataError, (dataset.root() / "manifest.json").string(), "split " + split,
              "tile counts that match the shards");
    slots[i] = {tile.key, model.predict(tile_input_from_dataset(tile)).graph};
    bar.advance();
  });
  metrics::GraphSet out;
  for (auto& [key, g] : slots) out.emplace(std::move(key), std::move(g));
  return out;
}

void write_submission(const metrics::GraphSet& graphs, const std::filesystem::path& path) {
  // Coordinates rounded to 1/1000 px: well below any metric's resolution, smaller files.
  auto round3 = [](double x) { return std::round(x * 1000.0) / 1000.0; };
  nlohmann::json tiles = nlohmann::json::object();
  for (const auto& [key, g] : graphs) {
    nlohmann::json nodes = nlohmann::json::array(), edges = nlohmann::json::array();
    for (const auto& n : g.nodes) nodes.push_back({round3(n.u), round3(n.v)});
    for (const auto& e : g.edges) edges.push_back({e[0], e[1]});
    nlohmann::json t = {{"nodes", nodes}, {"edges", edges}};
    if (!g.node_scores.empty()) {
      t["node_scores"] = nlohmann::json::array();
      for (double s : g.node_scores) t["node_scores"].push_back(round3(s));
    }
    if (!g.edge_scores.empty()) {
      t["edge_scores"] = nlohmann::json::array();
      for (double s : g.edge_scores) t["edge_scores"].push_back(round3(s));
    }
    tiles[key] = std::move(t);
  }
  const nlohmann::json doc = {{"schema_version", "1"}, {"tiles", tiles}};
  write_file_atomic(path, doc.dump() + "\n");
}

}  // namespace nsg::model

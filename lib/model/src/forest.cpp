#include "forest.h"

#include <algorithm>
#include <cmath>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "nsg/core/error.h"
#include "nsg/core/progress.h"
#include "nsg/model/tile_input.h"

namespace nsg::model::detail {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

uint64_t key_stream(const std::string& key) {
  uint64_t h = 1469598103934665603ull;
  for (unsigned char c : key) h = (h ^ c) * 1099511628211ull;
  return h;
}

std::vector<int> draw(std::vector<int> pool, int k, Rng& rng) {
  const size_t take = std::min(pool.size(), static_cast<size_t>(std::max(k, 0)));
  for (size_t i = 0; i < take; ++i) {
    const size_t j = i + static_cast<size_t>(rng.uniform_int(pool.size() - i));
    std::swap(pool[i], pool[j]);
  }
  pool.resize(take);
  return pool;
}

namespace {

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

}  // namespace

cv::Ptr<cv::ml::RTrees> train_forest(const ForestOptions& f, const cv::Mat& x, const cv::Mat& y, bool classifier,
                                     uint64_t seed) {
  NSG_CHECK(x.rows > 0, DataError, "", "training samples", "at least one sample (no tile with data in the split?)");
  cv::Mat var_type(1, x.cols + 1, CV_8U, cv::Scalar(cv::ml::VAR_ORDERED));
  if (classifier) var_type.at<uint8_t>(x.cols) = cv::ml::VAR_CATEGORICAL;
  const cv::Ptr<cv::ml::TrainData> data =
      cv::ml::TrainData::create(x, cv::ml::ROW_SAMPLE, y, cv::noArray(), cv::noArray(), cv::noArray(), var_type);
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

cv::Mat forest_map(const cv::ml::RTrees& forest, const FeatureMaps& f, int size, int stride) {
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

std::vector<Votes> window_votes(const cv::ml::RTrees& forest, const FeatureMaps& f, int size,
                                const std::vector<std::array<double, 2>>& anchors) {
  constexpr int kRadiusPx = 1;
  constexpr int kWindow = (2 * kRadiusPx + 1) * (2 * kRadiusPx + 1);
  std::vector<Votes> out(anchors.size(), Votes{});
  if (anchors.empty()) return out;
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
  for (int r = 0; r < x.rows; ++r) {
    Votes& v = out[static_cast<size_t>(r / kWindow)];
    for (int c = 0; c < raw.cols; ++c) {
      const int label = raw.at<int>(0, c);
      if (label >= 0 && label < kDirectionClasses)
        v[static_cast<size_t>(label)] += static_cast<float>(raw.at<int>(r + 1, c));
    }
  }
  return out;
}

std::vector<double> positive_fraction(const cv::ml::RTrees& forest, const cv::Mat& x) {
  std::vector<double> out(static_cast<size_t>(x.rows), 0.0);
  if (x.rows == 0) return out;
  cv::Mat raw;
  forest.getVotes(x, raw, 0);
  for (int r = 0; r < x.rows; ++r) {
    int total = 0, positive = 0;
    for (int c = 0; c < raw.cols; ++c) {
      total += raw.at<int>(r + 1, c);
      if (raw.at<int>(0, c) == 1) positive += raw.at<int>(r + 1, c);
    }
    out[static_cast<size_t>(r)] = total > 0 ? static_cast<double>(positive) / total : 0.0;
  }
  return out;
}

size_t split_tile_count(const io::Dataset& dataset, const std::string& split) {
  return static_cast<size_t>(io::tile_count(dataset.shards(split)));
}

void for_each_tile_parallel(const io::Dataset& dataset, const std::string& split, ThreadPool& pool,
                            const std::function<void(size_t, const io::DatasetTile&)>& fn) {
  size_t base = 0;
  for (const auto& shard : dataset.shards(split)) {
    const std::vector<io::DatasetTile> tiles = dataset.read_shard(shard);
    pool.parallel_for(tiles.size(), [&](size_t i) { fn(base + i, tiles[i]); });
    base += tiles.size();
  }
}

metrics::GraphSet predict_split(const io::Dataset& dataset, const std::string& split, ThreadPool& pool, bool progress,
                                const std::function<metrics::Graph(const TileInput&)>& predict) {
  dataset.require_split(split);  // `predict --split tst` named, not an empty submission
  const size_t total = split_tile_count(dataset, split);
  std::vector<std::pair<std::string, metrics::Graph>> slots(total);
  Progress bar("predict " + split, total, progress);
  for_each_tile_parallel(dataset, split, pool, [&](size_t i, const io::DatasetTile& tile) {
    NSG_CHECK(i < total, DataError, (dataset.root() / "manifest.json").string(), "split " + split,
              "tile counts that match the shards");
    slots[i] = {tile.key, predict(tile_input_from_dataset(tile))};
    bar.advance();
  });
  metrics::GraphSet out;
  for (auto& [key, g] : slots) out.emplace(std::move(key), std::move(g));
  return out;
}

}  // namespace nsg::model::detail

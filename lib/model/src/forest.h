#pragma once
// Internal helpers shared by training and prediction: seeded sampling, OpenCV forests
// trained reproducibly, forest outputs as maps and votes, and the split's tiles in parallel.
#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/ml.hpp>

#include "nsg/core/parallel.h"
#include "nsg/core/rng.h"
#include "nsg/io/dataset.h"
#include "nsg/model/features.h"
#include "nsg/model/graph_extraction.h"
#include "nsg/model/model.h"

namespace nsg::model::detail {

double seconds_since(std::chrono::steady_clock::time_point t0);
// FNV-1a of a tile key: the tile's own random stream, independent of visiting order.
uint64_t key_stream(const std::string& key);
// Up to k indices drawn without replacement (partial Fisher–Yates), in drawn order.
std::vector<int> draw(std::vector<int> pool, int k, Rng& rng);

// A forest trained on (x, y); the bagging RNG is seeded on the calling thread, so the
// forest depends only on the data and the seed.
cv::Ptr<cv::ml::RTrees> train_forest(const ForestOptions& f, const cv::Mat& x, const cv::Mat& y, bool classifier,
                                     uint64_t seed);
double mse(const cv::ml::RTrees& rt, const cv::Mat& x, const cv::Mat& y);

// A regression forest on every stride-th supported pixel, interpolated bilinearly to the
// full grid and clamped to [0, 1] (0 where no supported sample is near).
cv::Mat forest_map(const cv::ml::RTrees& forest, const FeatureMaps& f, int size, int stride);
// LaneDirNet's votes summed over the 3 × 3 pixels around each anchor, in one batch.
std::vector<Votes> window_votes(const cv::ml::RTrees& forest, const FeatureMaps& f, int size,
                                const std::vector<std::array<double, 2>>& anchors);
// Fraction of a two-class forest's trees voting for class 1, per row of x.
std::vector<double> positive_fraction(const cv::ml::RTrees& forest, const cv::Mat& x);

size_t split_tile_count(const io::Dataset& dataset, const std::string& split);
// Runs fn(tile index, tile) for every tile of the split: shard by shard, tiles of a shard
// in parallel (results must go to per-index slots).
void for_each_tile_parallel(const io::Dataset& dataset, const std::string& split, ThreadPool& pool,
                            const std::function<void(size_t, const io::DatasetTile&)>& fn);
// Every tile of the split through `predict` on `pool` (a progress bar), keyed by tile key:
// what `nsgraph predict` writes, for the forests and the ONNX network alike.
metrics::GraphSet predict_split(const io::Dataset& dataset, const std::string& split, ThreadPool& pool, bool progress,
                                const std::function<metrics::Graph(const TileInput&)>& predict);

}  // namespace nsg::model::detail

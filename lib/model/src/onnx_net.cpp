#include "nsg/model/onnx_net.h"

#include <cmath>

#include <opencv2/core/utility.hpp>
#include <opencv2/dnn.hpp>

#include "forest.h"
#include "nsg/core/error.h"
#include "nsg/core/progress.h"
#include "nsg/core/semantic_classes.h"
#include "nsg/model/direction.h"

namespace nsg::model {

namespace fs = std::filesystem;

namespace {

constexpr int kSemanticClasses = kSemanticClassCount;  // one-hot channels (nsg/core/semantic_classes.h)
constexpr int kTileMultiple = 64;                      // the pyramid's largest pool, 16 cells of 4 px

cv::Mat blob(int channels, int rows, int cols) {
  const int sizes[4] = {1, channels, rows, cols};
  return cv::Mat(4, sizes, CV_32F, cv::Scalar(0));
}

float* plane(cv::Mat& b, int c) { return b.ptr<float>(0, c); }

cv::dnn::Net read(const fs::path& file) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) throw IoError(file.string(), "", "an ONNX model file (missing)");
  cv::dnn::Net net;
  try {
    net = cv::dnn::readNetFromONNX(file.string());
  } catch (const cv::Exception& e) {
    throw ParseError(file.string(), "", std::string("an ONNX model OpenCV dnn can load (") + e.what() + ")");
  }
  if (net.empty()) throw ParseError(file.string(), "", "an ONNX model OpenCV dnn can load (empty network)");
  net.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  net.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
  return net;
}

// Channel c of an NCHW output as an h × w matrix (a copy).
cv::Mat channel(const cv::Mat& out, int c) {
  return cv::Mat(out.size[2], out.size[3], CV_32F, const_cast<float*>(out.ptr<float>(0, c))).clone();
}

}  // namespace

NetInputs encode_net_inputs(const TileInput& t) {
  const int h = t.lidar.rows, w = t.lidar.cols;
  NetInputs in{blob(2, h, w), blob(3, h, w), blob(kSemanticClasses, h, w), blob(3, h, w)};
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const size_t i = static_cast<size_t>(v) * w + u;
      const uint8_t l = t.lidar.at<uint8_t>(v, u);
      plane(in.lidar, 0)[i] = static_cast<float>(l) / 255.0f;
      plane(in.lidar, 1)[i] = l > 0 ? 1.0f : 0.0f;
      const cv::Vec3b rgb = t.rgb.at<cv::Vec3b>(v, u);
      for (int c = 0; c < 3; ++c) plane(in.rgb, c)[i] = static_cast<float>(rgb[c]) / 255.0f;
      const uint8_t s = t.semantic.at<uint8_t>(v, u);
      if (s < kSemanticClasses) plane(in.semantic, s)[i] = 1.0f;
      const float heading = t.vehicle.at<float>(v, u);
      if (heading >= 0.0f) {
        const double a = 2.0 * M_PI * static_cast<double>(heading);
        plane(in.vehicle, 0)[i] = static_cast<float>(std::sin(a));
        plane(in.vehicle, 1)[i] = static_cast<float>(std::cos(a));
        plane(in.vehicle, 2)[i] = 1.0f;
      }
    }
  }
  return in;
}

struct OnnxLaneNet::Impl {
  fs::path dense_file, pairs_file;
  cv::dnn::Net dense, pairs;
  NetGraphOptions options;
};

OnnxLaneNet::OnnxLaneNet(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
OnnxLaneNet::OnnxLaneNet(OnnxLaneNet&&) noexcept = default;
OnnxLaneNet::~OnnxLaneNet() = default;

OnnxLaneNet OnnxLaneNet::load(const fs::path& dense_onnx, const NetGraphOptions& options) {
  options.validate();
  auto m = std::make_unique<Impl>();
  m->dense_file = dense_onnx;
  m->pairs_file = fs::path(dense_onnx).replace_extension(".pairs.onnx");
  m->dense = read(m->dense_file);
  m->pairs = read(m->pairs_file);
  m->options = options;
  return OnnxLaneNet(std::move(m));
}

NetMaps OnnxLaneNet::dense(const TileInput& tile) {
  const int size = tile.size_px();
  NSG_CHECK(size > 0 && size % kTileMultiple == 0 && tile.lidar.cols == size, DataError, tile.key, "tile size",
            "a square tile whose side is a multiple of " + std::to_string(kTileMultiple) + " px, got " +
                std::to_string(tile.lidar.cols) + " × " + std::to_string(tile.lidar.rows));
  NetInputs in = encode_net_inputs(tile);
  Impl& m = *impl_;
  std::vector<cv::Mat> outs;
  try {
    m.dense.setInput(in.lidar, "lidar");
    m.dense.setInput(in.rgb, "rgb");
    m.dense.setInput(in.semantic, "semantic");
    m.dense.setInput(in.vehicle, "vehicle");
    m.dense.forward(outs, std::vector<std::string>{"heat", "offset", "direction", "features"});
  } catch (const cv::Exception& e) {
    throw ParseError(m.dense_file.string(), "", std::string("a model OpenCV dnn can run (") + e.what() + ")");
  }
  NSG_CHECK(outs.size() == 4 && outs[0].dims == 4 && outs[0].size[1] == 1 && outs[1].size[1] == 2 &&
                outs[2].size[1] == kDirectionClasses,
            ParseError, m.dense_file.string(), "outputs", "heat (1, 1, h, w), offset (1, 2, …), direction (1, 19, …)");
  NetMaps maps;
  maps.tile_size_px = size;
  maps.heat = channel(outs[0], 0);
  maps.offset_u = channel(outs[1], 0);
  maps.offset_v = channel(outs[1], 1);
  for (int c = 0; c < kDirectionClasses; ++c) maps.direction.push_back(channel(outs[2], c));
  for (int c = 0; c < outs[3].size[1]; ++c) maps.features.push_back(channel(outs[3], c));
  return maps;
}

std::vector<double> OnnxLaneNet::pair_scores(const cv::Mat& pair_inputs) {
  if (pair_inputs.rows == 0) return {};
  Impl& m = *impl_;
  cv::Mat out;
  try {
    m.pairs.setInput(pair_inputs, "pairs");
    out = m.pairs.forward("score");
  } catch (const cv::Exception& e) {
    throw ParseError(m.pairs_file.string(), "", std::string("a model OpenCV dnn can run (") + e.what() + ")");
  }
  NSG_CHECK(out.total() == static_cast<size_t>(pair_inputs.rows), ParseError, m.pairs_file.string(), "output score",
            "one score per pair");
  const float* p = out.ptr<float>();
  return std::vector<double>(p, p + pair_inputs.rows);
}

metrics::Graph OnnxLaneNet::predict(const TileInput& tile) {
  const NetGraphOptions& o = impl_->options;
  const NetMaps maps = dense(tile);
  const AnchorSet anchors = net_anchors(maps, o);
  const std::vector<std::array<int, 2>> pairs = candidate_pairs(anchors.points, o.pair_radius_px);
  const std::vector<double> scores = pair_scores(net_pair_inputs(maps.features, anchors.points, pairs, o));
  return net_graph(anchors, pairs, scores, maps.tile_size_px, o);
}

metrics::GraphSet predict_dataset_onnx(const fs::path& dense_onnx, const io::Dataset& dataset, const std::string& split,
                                       int threads, bool progress) {
  OnnxLaneNet net = OnnxLaneNet::load(dense_onnx);
  cv::setNumThreads(resolve_threads(threads));
  ThreadPool pool(1);  // one network: tiles one after another, OpenCV's threads inside
  return detail::predict_split(dataset, split, pool, progress,
                               [&](const TileInput& input) { return net.predict(input); });
}

}  // namespace nsg::model

#include "nsg/segment/model.h"

#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "nsg/core/error.h"

namespace nsg::segment {

namespace fs = std::filesystem;

struct SegmentationModel::Impl {
  fs::path file;
  cv::dnn::Net net;
  ModelInput input;
  std::vector<uint8_t> class_of_channel;  // C entries
  int channels = 0, out_w = 0, out_h = 0;
  cv::Mat resized, blob, small;

  // NCHW float32 blob of the image as the labels file says.
  void make_blob(const cv::Mat& rgb) {
    cv::resize(rgb, resized, cv::Size(input.width, input.height), 0, 0, cv::INTER_LINEAR);
    const int sizes[4] = {1, 3, input.height, input.width};
    blob.create(4, sizes, CV_32F);
    const size_t plane = static_cast<size_t>(input.width) * input.height;
    float* out = blob.ptr<float>();
    for (int y = 0; y < input.height; ++y) {
      const uint8_t* row = resized.ptr<uint8_t>(y);
      for (int x = 0; x < input.width; ++x) {
        const size_t i = static_cast<size_t>(y) * input.width + x;
        for (int c = 0; c < 3; ++c) {
          const int src = input.rgb ? c : 2 - c;  // the decoded image is RGB
          out[c * plane + i] = static_cast<float>((row[3 * x + src] * input.scale - input.mean[c]) / input.std[c]);
        }
      }
    }
  }

  cv::Mat forward() {
    net.setInput(blob);
    try {
      return net.forward();
    } catch (const cv::Exception& e) {
      throw ParseError(file.string(), "", std::string("a model OpenCV dnn can run (") + e.what() + ")");
    }
  }
};

SegmentationModel::SegmentationModel(const fs::path& onnx, const SegmentLabels& labels)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.file = onnx;
  std::error_code ec;
  if (!fs::is_regular_file(onnx, ec)) throw IoError(onnx.string(), "", "an ONNX model file (missing)");
  if (!labels.input)
    throw ParseError(labels.file, "/input", "the model's input size and normalisation (\"input\": {width, height, …})");
  m.input = *labels.input;
  try {
    m.net = cv::dnn::readNetFromONNX(onnx.string());
  } catch (const cv::Exception& e) {
    throw ParseError(onnx.string(), "", std::string("an ONNX model OpenCV dnn can load (") + e.what() + ")");
  }
  if (m.net.empty()) throw ParseError(onnx.string(), "", "an ONNX model OpenCV dnn can load (empty network)");
  m.net.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  m.net.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
  // A blank probe tells the output's shape before any image is read.
  const cv::Mat blank(m.input.height, m.input.width, CV_8UC3, cv::Scalar(0, 0, 0));
  m.make_blob(blank);
  const cv::Mat out = m.forward();
  std::string shape;
  for (int d = 0; d < out.dims; ++d) shape += (d ? "×" : "") + std::to_string(out.size[d]);
  if (out.dims != 4 || out.size[0] != 1 || out.type() != CV_32F)
    throw ParseError(
        onnx.string(), "",
        "a segmentation model whose output is N×C×h×w float32 class scores with N = 1 (got " + shape + ")");
  m.channels = out.size[1];
  m.out_h = out.size[2];
  m.out_w = out.size[3];
  if (labels.max_channel() >= m.channels)
    throw ParseError(labels.file, "/classes/" + std::to_string(labels.max_channel()),
                     "output channels of the model " + onnx.filename().string() + " (0.." +
                         std::to_string(m.channels - 1) + ", its output is " + shape + ")");
  m.class_of_channel.resize(static_cast<size_t>(m.channels));
  for (int c = 0; c < m.channels; ++c)
    m.class_of_channel[static_cast<size_t>(c)] = labels.class_of(static_cast<size_t>(c));
}

SegmentationModel::~SegmentationModel() = default;
SegmentationModel::SegmentationModel(SegmentationModel&&) noexcept = default;
SegmentationModel& SegmentationModel::operator=(SegmentationModel&&) noexcept = default;

int SegmentationModel::channels() const { return impl_->channels; }
std::pair<int, int> SegmentationModel::output_size() const { return {impl_->out_w, impl_->out_h}; }

void SegmentationModel::segment(const nuscenes::RgbImage& image, nuscenes::GrayImage& mask, int scale_denom) {
  Impl& m = *impl_;
  const cv::Mat rgb(image.height, image.width, CV_8UC3, const_cast<uint8_t*>(image.pixels.data()));
  m.make_blob(rgb);
  const cv::Mat out = m.forward();
  // Argmax over channels (the first of equal scores wins), then our class.
  m.small.create(m.out_h, m.out_w, CV_8U);
  const size_t plane = static_cast<size_t>(m.out_w) * m.out_h;
  const float* scores = out.ptr<float>();
  for (size_t i = 0; i < plane; ++i) {
    int best = 0;
    float best_score = scores[i];
    for (int c = 1; c < m.channels; ++c) {
      const float s = scores[c * plane + i];
      if (s > best_score) best = c, best_score = s;
    }
    m.small.data[i] = m.class_of_channel[static_cast<size_t>(best)];
  }
  if (scale_denom < 1) throw InternalError("", "segment", "a mask scale denominator >= 1");
  mask.width = (image.width + scale_denom - 1) / scale_denom;
  mask.height = (image.height + scale_denom - 1) / scale_denom;
  mask.pixels.resize(static_cast<size_t>(mask.width) * mask.height);
  cv::Mat full(mask.height, mask.width, CV_8U, mask.pixels.data());
  // Pixel-centre nearest neighbour (INTER_NEAREST has a half-pixel shift).
  cv::resize(m.small, full, full.size(), 0, 0, cv::INTER_NEAREST_EXACT);
}

std::vector<uint8_t> encode_mask_png(const nuscenes::GrayImage& mask) {
  const cv::Mat m(mask.height, mask.width, CV_8U, const_cast<uint8_t*>(mask.pixels.data()));
  std::vector<uint8_t> png;
  if (!cv::imencode(".png", m, png, {cv::IMWRITE_PNG_COMPRESSION, 1}))
    throw InternalError("", "", "OpenCV could not encode a PNG mask");
  return png;
}

int set_opencv_threads(int threads) {
  const int previous = cv::getNumThreads();
  cv::setNumThreads(threads);
  return previous;
}

}  // namespace nsg::segment

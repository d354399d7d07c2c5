#pragma once
// A semantic-segmentation model run with OpenCV's dnn module (ONNX): an RGB image in, a
// class-id mask of our classes out (argmax over the N×C×h×w output's channels, mapped by
// the labels file, resized to the image with nearest neighbour). OpenCV stays behind a
// pimpl. One instance per thread: inference is not thread-safe.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "nsg/nuscenes/camera.h"
#include "nsg/nuscenes/semantic_mask.h"
#include "nsg/segment/labels.h"

namespace nsg::segment {

class SegmentationModel {
 public:
  // Loads the model and runs it once on a blank input to learn its output: throws IoError
  // (missing file), ParseError naming the model file when it is not an ONNX model OpenCV
  // can load or when its output is not N×C×h×w with N = 1, and ParseError naming the labels
  // file when it has no `input` or names a channel ≥ C.
  SegmentationModel(const std::filesystem::path& onnx, const SegmentLabels& labels);
  ~SegmentationModel();
  SegmentationModel(SegmentationModel&&) noexcept;
  SegmentationModel& operator=(SegmentationModel&&) noexcept;

  int channels() const;                     // C
  std::pair<int, int> output_size() const;  // (w, h) of the output
  // The class-id mask of `image` (interleaved RGB) at 1/scale_denom of its size (sides
  // rounded up; 1 = the image's size), nearest from the model's output.
  void segment(const nuscenes::RgbImage& image, nuscenes::GrayImage& mask, int scale_denom = 1);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// 8-bit grayscale PNG bytes of a mask (what nuscenes::read_semantic_mask reads), zlib
// level 1 (masks compress well even so); deterministic for the same pixels.
std::vector<uint8_t> encode_mask_png(const nuscenes::GrayImage& mask);

// Sets OpenCV's own worker threads (cv::setNumThreads) for the calling process and returns
// the previous value: `segment` runs one image per thread with OpenCV single-threaded.
int set_opencv_threads(int threads);

}  // namespace nsg::segment

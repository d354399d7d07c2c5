#pragma once
// `nsgraph segment`: runs a semantic-segmentation model (ONNX, OpenCV dnn) on
// every key-frame camera image of a release — the images `generate` colours from — and
// writes class-id masks of our classes (samples/semantic-classes.json, 255 = void) where
// `generate` reads them: <out>/<CHANNEL>/<jpeg basename>.png, so that
// `generate --set camera.semantic_root=<out>` uses them.
//
// Images are work items in sample_data order; a share (ShareSpec, as generate) does the
// items j with j % count == index. A mask that exists and reads back as a valid mask of
// the image's size at mask_scale_denom is skipped, so a rerun resumes; masks are written to a temp name and
// renamed. The bytes of a mask depend only on the image, the model and the labels file:
// not on --threads (one image per thread, OpenCV itself single-threaded) nor on shares.
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "nsg/pipeline/generate.h"

namespace nsg::pipeline {

struct SegmentOptions {
  std::filesystem::path dataroot;
  std::string version = "v1.0-trainval";
  std::filesystem::path model;        // .onnx
  std::filesystem::path labels;       // schemas/v1/segment-labels.schema.json
  std::filesystem::path out;          // mask root
  std::vector<std::string> channels;  // camera channels; empty = every camera
  std::filesystem::path schemas_dir;  // empty = validate::find_schemas_dir()
  ShareSpec share;
  int threads = 0;  // 0 = all cores
  // Masks are written at 1/n of the image's size (sides rounded up): by default the scale
  // generate samples at (camera.jpeg_scale_denom 2), so its decode reads no pixel for
  // nothing; 1 = full size. generate reads any n (raster/color_layer.h).
  int mask_scale_denom = 2;
  bool progress = true;
  void validate() const;  // ConfigError naming the option
};

struct SegmentSummary {
  size_t images = 0;     // key-frame camera images of the selected channels (whole run)
  size_t mine = 0;       // this share's
  size_t written = 0;    // masks written this run
  size_t skipped = 0;    // valid masks already there
  double seconds = 0.0;  // wall time of the images written
  double images_per_s() const { return seconds > 0.0 ? static_cast<double>(written) / seconds : 0.0; }
};

// Throws ConfigError (options; a channel that is not a camera of the release), IoError /
// ParseError naming the model or labels file (not ONNX, output not N×C×h×w, unknown class,
// channel outside the output), DataError naming a JPEG whose size is not its
// sample_data's, and the release loader's errors. All exit 2.
SegmentSummary segment_cameras(const SegmentOptions& options);

}  // namespace nsg::pipeline

// Frames for nsgraph.frames: the scorer of `nsgraph score --frames` (metrics::
// score_frames_submission) and the camera JPEG decoder of the library (libjpeg-turbo,
// sizes checked from the header before any allocation).
#include <cstring>
#include <filesystem>

#include "bindings.h"
#include "convert.h"
#include "nsg/core/issues.h"
#include "nsg/core/strings.h"
#include "nsg/metrics/frames.h"
#include "nsg/nuscenes/camera.h"

namespace nsg::py_bind {
namespace {

// (report JSON text or None, issues, issues as text).
py::tuple score_frames(const std::string& ground_truth, const std::string& results, const std::string& split,
                       bool verify, int64_t max_file_bytes, bool graph_metrics) {
  metrics::FramesScoreInput in;
  in.ground_truth = ground_truth;
  in.results = results;
  in.split = split;
  in.verify = verify;
  in.graph_metrics = graph_metrics;
  if (max_file_bytes > 0) in.limits.max_file_bytes = max_file_bytes;
  metrics::ScoredFrames scored;
  {
    py::gil_scoped_release release;
    scored = metrics::score_frames_submission(in);
  }
  py::object report = py::none();
  if (scored.report) report = py::str(metrics::frames_report_to_json(*scored.report).dump());
  return py::make_tuple(report, issues_to_py(scored.issues), printable_utf8(scored.issues.format()));
}

// (H, W, 3) uint8 RGB of a JPEG file, at 1/scale (1, 2 or 4).
py::array_t<uint8_t> decode_jpeg(const std::string& path, int scale) {
  nuscenes::RgbImage image;
  {
    py::gil_scoped_release release;
    nuscenes::JpegDecoder decoder;
    decoder.decode_file(path, static_cast<nuscenes::JpegScale>(scale), image);
  }
  py::array_t<uint8_t> out({image.height, image.width, 3});
  std::memcpy(out.mutable_data(), image.pixels.data(), image.pixels.size());
  return out;
}

}  // namespace

void bind_frames(py::module_& m) {
  m.def("score_frames", &score_frames, py::arg("ground_truth"), py::arg("results"), py::arg("split"),
        py::arg("verify") = true, py::arg("max_file_bytes") = 0, py::arg("graph_metrics") = false);
  m.def("decode_jpeg", &decode_jpeg, py::arg("path"), py::arg("scale") = 1);
}

}  // namespace nsg::py_bind

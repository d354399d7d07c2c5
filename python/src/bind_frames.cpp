// Frames for nsgraph.frames: an export's manifest and records through the library's one
// reader of them (metrics/frames_documents.h), the scorer of `nsgraph score --frames`
// (metrics::score_frames_submission) and the camera JPEG decoder of the library
// (libjpeg-turbo, sizes checked from the header before any allocation).
#include <cstring>
#include <filesystem>
#include <map>

#include "bindings.h"
#include "convert.h"
#include "nsg/core/error.h"
#include "nsg/core/issues.h"
#include "nsg/core/strings.h"
#include "nsg/frames/render.h"
#include "nsg/metrics/frames.h"
#include "nsg/nuscenes/camera.h"

namespace nsg::py_bind {
namespace {

py::list triple_to_py(const std::array<double, 3>& v) {
  py::list out;
  for (const double x : v) out.append(x);
  return out;
}

py::list matrix_to_py(const std::array<std::array<double, 3>, 3>& m) {
  py::list rows;
  for (const auto& row : m) rows.append(triple_to_py(row));
  return rows;
}

py::dict transform_to_py(const metrics::FrameTransform& t) {
  py::dict d;
  d["rotation"] = matrix_to_py(t.rotation);
  d["translation"] = triple_to_py(t.translation);
  return d;
}

// (P, 3) float64 of a centerline's points.
py::array_t<double> points_to_numpy(const std::vector<metrics::Point3>& points) {
  py::array_t<double> a({static_cast<py::ssize_t>(points.size()), py::ssize_t{3}});
  if (!points.empty()) std::memcpy(a.mutable_data(), points.data(), points.size() * sizeof(points[0]));
  return a;
}

// Version 2's lane segments (lines as (P, 3) arrays), areas and topology_lsls ((n, n) uint8).
void add_map_elements(const metrics::FrameRecord& r, py::dict& annotation) {
  py::list segments;
  for (const metrics::FrameRecordLaneSegment& s : r.lane_segments) {
    py::dict segment;
    segment["id"] = s.id;
    segment["centerline"] = points_to_numpy(s.centerline);
    segment["left_laneline"] = points_to_numpy(s.left_laneline);
    segment["left_laneline_type"] = s.left_type;
    segment["right_laneline"] = points_to_numpy(s.right_laneline);
    segment["right_laneline_type"] = s.right_type;
    segment["is_intersection_or_connector"] = s.is_connector;
    segments.append(segment);
  }
  py::list areas;
  for (const metrics::FrameRecordArea& a : r.areas) {
    py::dict area;
    area["id"] = a.id;
    area["category"] = a.category;
    area["points"] = points_to_numpy(a.points);
    areas.append(area);
  }
  const auto n = static_cast<py::ssize_t>(r.lane_segments.size());
  py::array_t<uint8_t> topology({n, n});
  if (n > 0) std::memcpy(topology.mutable_data(), r.topology_lsls.data(), r.topology_lsls.size());
  py::list lste;
  for (py::ssize_t i = 0; i < n; ++i) lste.append(py::list());
  annotation["lane_segment"] = segments;
  annotation["area"] = areas;
  annotation["topology_lsls"] = topology;
  annotation["topology_lste"] = lste;
}

// A checked record in the record's own layout (docs/frames.md "Layout"), points as (P, 3)
// arrays and topology_lclc as an (n, n) uint8 array (version 2: lane segments and areas too):
// what nsgraph.frames.Dataset.record gives.
py::dict record_to_py(const metrics::FrameRecord& r) {
  py::dict meta;
  meta["source"] = r.meta_data.source;
  meta["source_id"] = r.meta_data.source_id;
  meta["version"] = r.meta_data.version;
  meta["location"] = r.meta_data.location;
  meta["map_version"] = r.meta_data.map_version;
  meta["region"] = r.meta_data.region ? py::object(py::str(*r.meta_data.region)) : py::none();
  py::dict sensor;
  for (const metrics::FrameCamera& c : r.cameras) {
    py::dict cam, intrinsic;
    cam["image_path"] = c.image_path;
    cam["timestamp"] = c.timestamp_us;
    cam["width"] = c.width;
    cam["height"] = c.height;
    cam["extrinsic"] = transform_to_py(c.extrinsic);
    intrinsic["K"] = matrix_to_py(c.k);
    intrinsic["distortion"] = py::list();
    cam["intrinsic"] = intrinsic;
    cam["ego_pose"] = transform_to_py(c.ego_pose);
    sensor[py::str(c.channel)] = cam;
  }
  py::list lanes;
  for (const metrics::FrameRecordCenterline& c : r.centerlines) {
    py::dict lane;
    lane["id"] = c.id;
    lane["points"] = points_to_numpy(c.points);
    lane["points_2m"] = points_to_numpy(c.points_2m);
    lane["is_intersection_or_connector"] = c.is_connector;
    lane["lane_token"] = c.lane_token;
    lane["starts_at_lane_start"] = c.starts_at_lane_start;
    lane["ends_at_lane_end"] = c.ends_at_lane_end;
    lanes.append(lane);
  }
  const auto n = static_cast<py::ssize_t>(r.centerlines.size());
  py::array_t<uint8_t> topology({n, n});
  if (n > 0) std::memcpy(topology.mutable_data(), r.topology_lclc.data(), r.topology_lclc.size());
  py::dict annotation;
  annotation["lane_centerline"] = lanes;
  annotation["traffic_element"] = py::list();
  annotation["topology_lclc"] = topology;
  py::list lcte;
  for (py::ssize_t i = 0; i < n; ++i) lcte.append(py::list());
  annotation["topology_lcte"] = lcte;
  if (r.has_map_elements()) add_map_elements(r, annotation);
  py::dict d;
  d["schema_version"] = r.schema_version;
  d["version"] = r.version;
  d["segment_id"] = r.segment_id;
  d["meta_data"] = meta;
  d["timestamp"] = r.timestamp_us;
  d["sample_token"] = r.sample_token;
  d["split"] = r.split;
  d["sensor"] = sensor;
  d["pose"] = transform_to_py(r.pose);
  d["annotation"] = annotation;
  if (r.overlap) d["overlap"] = *r.overlap;
  return d;
}

// An export read as the C++ tools read it: the manifest when opened, a record when asked
// (its size and type checked before it is read, then every field); errors are nsgraph.errors'
// ParseError / DataError / IoError naming the file, the JSON pointer and what was expected.
class FramesExport {
 public:
  FramesExport(const FramesExport&) = delete;  // by_path_ points into manifest_
  FramesExport& operator=(const FramesExport&) = delete;
  explicit FramesExport(const std::string& root) {
    {
      py::gil_scoped_release release;
      manifest_ = metrics::read_frames_manifest(root);
    }
    for (const metrics::FramesListedFile& f : manifest_.files) by_path_.emplace(f.path, &f);
    release_ = manifest_.release_folder().string();
  }

  py::object manifest() const { return json_to_py(manifest_.document); }
  // source.dataroot resolved against the export's folder.
  const std::string& dataroot() const { return release_; }
  bool copy_images() const { return manifest_.copy_images; }

  std::vector<std::string> records(const std::string& split) const {
    std::vector<std::string> out;
    for (const metrics::FramesListedFile* f : manifest_.records(split)) out.push_back(f->path);
    return out;
  }

  py::dict record(const std::string& path, bool verify) const {
    const auto it = by_path_.find(path);
    NSG_CHECK(it != by_path_.end(), ConfigError, manifest_.file.string(), path, "a file the manifest lists");
    metrics::FrameRecord r;
    {
      py::gil_scoped_release release;
      r = metrics::read_listed_record(manifest_, *it->second, verify);
    }
    return record_to_py(r);
  }

 private:
  metrics::FramesManifest manifest_;
  std::string release_;
  std::map<std::string, const metrics::FramesListedFile*> by_path_;  // into manifest_.files
};

// (report JSON text or None, issues, issues as text).
py::tuple score_frames(const std::string& ground_truth, const std::string& results, const std::string& split,
                       bool verify, int64_t max_file_bytes, bool graph_metrics, double max_seconds) {
  metrics::FramesScoreInput in;
  in.ground_truth = ground_truth;
  in.results = results;
  in.split = split;
  in.verify = verify;
  in.graph_metrics = graph_metrics;
  in.max_seconds = max_seconds;
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

// `nsgraph frames render`: the files written (relative to out) and the ground-truth pieces in
// view per camera.
py::tuple render_frame(const std::string& export_dir, const std::string& frame, const std::string& out,
                       const std::string& split, const std::string& submission, bool overwrite, double bev_px_per_m) {
  frames::RenderRequest r;
  r.export_dir = export_dir;
  r.frame = frame;
  r.out = out;
  r.split = split;
  r.submission = submission;
  r.overwrite = overwrite;
  r.bev_px_per_m = bev_px_per_m;
  frames::RenderedFrame done;
  {
    py::gil_scoped_release release;
    done = frames::render_frame(r);
  }
  py::dict pieces;
  for (const auto& [channel, n] : done.truth_pieces_per_camera) pieces[py::str(channel)] = n;
  return py::make_tuple(done.files, pieces);
}

}  // namespace

void bind_frames(py::module_& m) {
  m.def("score_frames", &score_frames, py::arg("ground_truth"), py::arg("results"), py::arg("split"),
        py::arg("verify") = true, py::arg("max_file_bytes") = 0, py::arg("graph_metrics") = false,
        py::arg("max_seconds") = metrics::FramesScoreInput{}.max_seconds);
  py::class_<FramesExport>(m, "FramesExport",
                           "An `nsgraph frames` export through the library's reader (metrics/frames_documents.h)")
      .def(py::init<const std::string&>(), py::arg("root"))
      .def_property_readonly("manifest", &FramesExport::manifest, "The manifest as read (a dict)")
      .def_property_readonly("dataroot", &FramesExport::dataroot, "source.dataroot")
      .def_property_readonly("copy_images", &FramesExport::copy_images, "config.copy_images")
      .def("records", &FramesExport::records, py::arg("split"), "The paths of a split's records, in manifest order")
      .def("record", &FramesExport::record, py::arg("path"), py::arg("verify") = true,
           "One listed record, checked (size and type before it is read, sha256 when verify, every field)");
  m.def("decode_jpeg", &decode_jpeg, py::arg("path"), py::arg("scale") = 1);
  m.def("render_frame", &render_frame, py::arg("export_dir"), py::arg("frame"), py::arg("out"), py::arg("split"),
        py::arg("submission"), py::arg("overwrite"), py::arg("bev_px_per_m"));
}

}  // namespace nsg::py_bind

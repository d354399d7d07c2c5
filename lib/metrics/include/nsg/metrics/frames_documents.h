#pragma once
// The documents of an `nsgraph frames` export (docs/frames.md "Layout"), one typed model and
// one reader each: the frames manifest (manifest.json, kind "nsgraph-frames"), the frame
// record (<split>/<scene>/info/<timestamp>.json, OpenLane-V2's info layout) and the frames
// results (an OpenLane-V2 results document, read_frames_results). Every reader of them goes
// through these: the scorer (`score --frames`), `predict --frames` (frames::read_export_frames)
// and the Python package (nsgraph.frames, through _nsgraph). Each reader bounds the bytes it
// reads before it reads them, applies the format's limits itself and names every defect by
// file, JSON pointer and what was expected (exit 2), or, for a results file (a stranger's
// submission), as Issues (exit 1).
//
// Why in metrics (#9 in lib/CMakeLists.txt): the writer's module, frames (#16), lies above
// metrics and links it, while the scorer in metrics needs the readers, so they cannot live
// beside the writer; metrics already owns the strict simdjson parse every frame document goes
// through (src/frames_json.h; records are read at GB/s by it, and a frames split holds tens of
// thousands). io (#7) would need the scorer's FrameCenterlines and simdjson moved down for no
// reader of its own.
#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "nsg/core/issues.h"

namespace nsg::metrics {

using Point3 = std::array<double, 3>;

// A lane segment's lines (OpenLane-V2 v2.1's map element bucket), ego frame, m.
struct SegmentLines {
  std::vector<Point3> centerline, left, right;
};
// An area: category 1 pedestrian crossing, 2 road boundary.
struct AreaPoints {
  int category = 1;
  std::vector<Point3> points;
};

// One frame's centerlines: the ground truth's (confidence unused, topology 0/1) or a
// prediction's. topology is n × n, row-major: [i · n + j] = the link i → j.
// With `has_map_elements`, also its lane segments (topology_lsls, as topology) and areas.
struct FrameCenterlines {
  std::vector<std::vector<Point3>> lanes;
  std::vector<double> confidence;
  std::vector<double> topology;
  bool has_centerlines = true;  // false: a results frame of lane segments only
  bool has_map_elements = false;
  std::vector<SegmentLines> segments;
  std::vector<double> segment_confidence;
  std::vector<double> topology_lsls;
  std::vector<AreaPoints> areas;
  std::vector<double> area_confidence;
};

// Points OpenLane-V2's lane-segment collect() gives the ground truth's lines (its
// data/OpenLane-V2/preprocess-ls.py): 10 per centerline and laneline, 20 per area.
inline constexpr int kLaneSegmentLinePoints = 10;
inline constexpr int kAreaPoints = 20;

// `n` points of `line` as collect()'s _fix_pts_interpolate places them: shapely's
// LineString.interpolate at np.linspace(0, length, n), the length and the walk in x, y (z
// interpolated on the way), rounded to float32 as it stores them.
std::vector<Point3> interpolate_like_collect(const std::vector<Point3>& line, int n);

// Ordered frames (the order of the ground truth: an export's records by path).
using FrameSet = std::vector<std::pair<std::string, FrameCenterlines>>;

// What an export's manifest and records may hold (our own files, still read as a stranger's:
// an export is copied, shared and unpacked from archives). Beyond a limit is a ParseError.
struct FramesDocumentLimits {
  // The manifest lists every record and image: a full nuScenes export (34 149 key frames,
  // 6 cameras each, images copied) is ~240 000 entries, ~40 MiB.
  int64_t max_manifest_bytes = int64_t{256} << 20;
  int64_t max_manifest_files = 5'000'000;
  // A record of the default window is ~30 KiB; a 1 km window with every lane of a city ~10 MiB.
  int64_t max_record_bytes = int64_t{64} << 20;
  int64_t max_json_values = 50'000'000;
  int max_depth = 16;        // a record nests 6 deep (sensor.CAM.extrinsic.rotation[r][c])
  int64_t max_cameras = 64;  // nuScenes has 6
  int64_t max_centerlines = 100'000;
  int64_t max_points_per_centerline = 100'000;
  // Ego-frame points and every translation (nuScenes' maps span < 3 km), metres.
  double max_abs_coordinate_m = 1e7;
};

// One file of an export as its manifest lists it.
struct FramesListedFile {
  std::string path;  // relative to the export, stays inside it (no "..", not absolute)
  int64_t bytes = 0;
  std::string sha256;  // 64 lowercase hex digits
};

// The frames' window in the ego frame (config.window; frames::WindowM), metres.
struct FramesWindowM {
  double x_min_m = 0.0, x_max_m = 0.0, y_min_m = 0.0, y_max_m = 0.0;
};

// manifest.json of an export (schemas/v1/frames-manifest.schema.json): the fields its readers
// use, typed and checked; `document` is the whole of it as read (counts and leakage figures,
// shown to users, not relied on).
struct FramesManifest {
  std::filesystem::path export_dir;
  std::filesystem::path file;           // export_dir / "manifest.json": what every error names
  std::string dataset_manifest_sha256;  // source.dataset_manifest_sha256: the dataset it was cut from
  std::string dataroot;                 // source.dataroot: the release of referenced images
  FramesWindowM window;                 // config.window
  int centerline_points = 11;           // config.centerline_points
  bool copy_images = false;             // config.copy_images: image paths relative to the export
  std::vector<FramesListedFile> files;  // every file but the manifest, in its order
  nlohmann::json document;

  // The records of `split` (paths "<split>/…/info/…"), in the manifest's order.
  std::vector<const FramesListedFile*> records(const std::string& split) const;
  // The release of referenced images: `dataroot`, which frames writes relative to the export's
  // folder, resolved against it (nsg::resolve_document_path).
  std::filesystem::path release_folder() const;
};

// Reads `<export_dir>/manifest.json`: a regular file within limits.max_manifest_bytes
// (measured before it is read), strict JSON, kind "nsgraph-frames", every field above of its
// type and range, every listed path inside the export and listed once. IoError (missing),
// ParseError naming the manifest, the JSON pointer and the expectation.
FramesManifest read_frames_manifest(const std::filesystem::path& export_dir, const FramesDocumentLimits& limits = {});

// The bytes of a file the manifest lists, before anything is read: no symlink on its path
// inside the export (lstat: a link could lead out of it), a regular file (not a device, a
// FIFO, a folder), its size equal to the manifest's `bytes` and within `max_bytes`; then at
// most that many bytes are read and, when `verify`, their sha256 compared. DataError naming
// the file otherwise (IoError when it is missing or unreadable).
std::string read_listed_file(const FramesManifest& manifest, const FramesListedFile& listed, int64_t max_bytes,
                             bool verify);

// A 3-D rigid transform as the records write it: rotation 3 × 3 (row-major), translation (m).
struct FrameTransform {
  std::array<std::array<double, 3>, 3> rotation{};
  std::array<double, 3> translation{};
};

// sensor.<channel> of a record.
struct FrameCamera {
  std::string channel;     // CAM_FRONT, …, in the record's order
  std::string image_path;  // inside the release's dataroot, or the export (copy_images): no "..", not absolute
  int64_t timestamp_us = 0;
  int64_t width = 0, height = 0;
  FrameTransform extrinsic;  // camera → ego
  std::array<std::array<double, 3>, 3> k{};
  FrameTransform ego_pose;  // ego → global at the image's time
};

// annotation.lane_centerline[i] of a record.
struct FrameRecordCenterline {
  int64_t id = 0;
  std::vector<Point3> points;     // centerline_points, ego frame, m
  std::vector<Point3> points_2m;  // the lane graph's nodes and the cut points
  bool is_connector = false;      // is_intersection_or_connector
  std::string lane_token;
  bool starts_at_lane_start = false;
  bool ends_at_lane_end = false;
};

// A lane segment of a version-2 record (OpenLane-V2 v2.1's map element bucket): a
// centerline with its left and right lanelines, ego frame, m.
struct FrameRecordLaneSegment {
  int64_t id = 0;  // its centerline's
  std::vector<Point3> centerline, left_laneline, right_laneline;
  int left_type = 0, right_type = 0;  // 0 none, 1 solid, 2 dash
  bool is_connector = false;          // is_intersection_or_connector
};

// An area of a version-2 record: category 1 pedestrian crossing (its outline, closed), 2 road
// boundary (a polyline).
struct FrameRecordArea {
  int64_t id = 0;
  int category = 1;
  std::vector<Point3> points;
};

// A frame record's versions (its "version"): 2 adds the lane segments and areas; a reader
// takes both, `nsgraph frames` writes version 2.
inline constexpr const char* kFrameRecordVersion = "nsgraph-frames-2";
inline constexpr const char* kFrameRecordVersion1 = "nsgraph-frames-1";

// A frame record (schemas/v1/frame.schema.json), every field typed and checked.
struct FrameRecord {
  std::string schema_version;
  std::string version;  // "nsgraph-frames-1", or "nsgraph-frames-2" with lane segments and areas
  std::string segment_id;
  std::string sample_token;
  std::string split;
  int64_t timestamp_us = 0;
  struct MetaData {
    std::string source, source_id, version, location, map_version;
    std::optional<std::string> region;  // null for split_preset scenes-random
  } meta_data;
  std::vector<FrameCamera> cameras;
  FrameTransform pose;  // ego → global at the LIDAR_TOP key frame
  std::vector<FrameRecordCenterline> centerlines;
  std::vector<uint8_t> topology_lclc;  // n × n of 0/1, row-major
  // Version 2 (empty in a version-1 record): one lane segment per centerline, same order.
  std::vector<FrameRecordLaneSegment> lane_segments;
  std::vector<FrameRecordArea> areas;
  std::vector<uint8_t> topology_lsls;  // n × n of 0/1, row-major
  std::optional<bool> overlap;         // only with overlap: flag

  // Version 2: lane_segments, areas and topology_lsls were read (empty in version 1).
  bool has_map_elements() const { return version != kFrameRecordVersion1; }

  // The scorer's view: the centerlines' points and topology_lclc.
  FrameCenterlines truth() const;
  // OpenLane-V2's name of the frame, the identifier (split, segment_id, timestamp) its
  // results dicts are keyed by, written "split/segment_id/timestamp": the record's path
  // without "info/" and ".json". A results file may key a frame so or by sample_token.
  std::string identifier() const;
};

// One record's text (`file` names it in errors): strict JSON within `limits`, every field of
// the schema present with its type, shapes consistent (topology n × n, 3 × 3 matrices),
// numbers finite and within range. ParseError naming the file, the JSON pointer and what was
// expected.
FrameRecord read_frame_record(std::string_view text, const std::string& file, const FramesDocumentLimits& limits = {});

// One record the manifest lists, read through read_listed_file (within
// limits.max_record_bytes) and read_frame_record; a record whose `split` is not the folder its
// path lies in is a DataError.
FrameRecord read_listed_record(const FramesManifest& manifest, const FramesListedFile& listed, bool verify,
                               const FramesDocumentLimits& limits = {});

// Calls fn(record, listed) for every record of `split` the manifest lists, in its order, each
// read by read_listed_record.
void for_each_frame_record(const FramesManifest& manifest, const std::string& split, bool verify,
                           const std::function<void(const FrameRecord& record, const FramesListedFile& listed)>& fn,
                           const FramesDocumentLimits& limits = {});

// What a results file may hold, checked before anything is measured (docs/scoring-limits.md).
struct FrameResultsLimits {
  int64_t max_centerlines_per_frame = 1000;  // OpenLane-V2's frames hold < 100
  int64_t max_points_per_centerline = 1000;  // its ground truth has 11 (evaluated) to 201
  // nsgraph's graph metrics score each frame as a tile: its points are the nodes and its
  // links (probability > 0.5) edges, within the tile limits (5 000 nodes, 10 000 edges).
  int64_t max_points_per_frame = 5'000;
  int64_t max_links_per_frame = 5'000;
  // Chamfer and Fréchet compare every ground-truth point with every predicted point of a
  // frame: the product of the two point counts (5.5e7 pairs scored in 0.43 s on one core).
  int64_t max_point_pairs_per_frame = 100'000'000;
  double max_abs_coordinate_m = 1e5;
  int64_t max_file_bytes = int64_t{128} << 20;  // as for tiles (--max-file-mb)
  int64_t max_json_values = 50'000'000;
  int max_depth = 16;  // the format nests 7 deep
};

// An OpenLane-V2 results document in JSON: {"results": {token: {"predictions":
// {"lane_centerline": [{"id", "points": [[x, y, z], …], "confidence"}], "topology_lclc":
// n × n}}}} (other keys are allowed and ignored). Problems are Issues (checks
// "frames.results.*", subject "<file>:<JSON pointer>"); nullopt when there are any. Nothing
// a file holds throws but IoError (a missing or unreadable file).
std::optional<FrameSet> read_frames_results(const std::filesystem::path& file, const FrameResultsLimits& limits,
                                            Issues& issues);

}  // namespace nsg::metrics

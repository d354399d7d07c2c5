// The readers of an export's manifest and records (frames_documents.h): the bytes bounded
// before they are read, then every field typed, checked and named by its JSON pointer.
#include "nsg/metrics/frames_documents.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <iterator>
#include <limits>
#include <unordered_set>

#include "frames_json.h"
#include "nsg/core/error.h"
#include "nsg/core/files.h"
#include "nsg/core/json.h"
#include "nsg/core/sha256.h"
#include "nsg/core/strings.h"
#include "nsg/validate/submission.h"

namespace nsg::metrics {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kManifestKind = "nsgraph-frames";
constexpr double kWindowLimitM = 200.0;     // frames' config range of a window edge
constexpr int kMaxCenterlinePoints = 1000;  // frames' config range of centerline_points
// A rotation matrix's entries lie in [-1, 1]; the records write them unrounded.
constexpr double kMaxRotationEntry = 1.0 + 1e-6;
constexpr int64_t kMaxImageSidePx = 1'000'000;

// --- Bounded reads ------------------------------------------------------------------------

// Closes a descriptor on every path out.
struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

// Opens `path` (O_NOFOLLOW when `no_symlink`; O_NONBLOCK so a FIFO does not block the open)
// and checks what it is before a byte is read: a regular file of at most `max_bytes`, and of
// exactly `expected_bytes` when that is ≥ 0. fstat on the open descriptor: what is measured
// is what is read. Then reads exactly that many bytes.
std::string read_regular_file(const fs::path& path, bool no_symlink, int64_t expected_bytes, int64_t max_bytes,
                              const std::string& record, const std::string& listed_by) {
  Fd f;
  f.fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK | (no_symlink ? O_NOFOLLOW : 0));
  if (f.fd < 0) {
    if (errno == ELOOP)
      throw DataError(path.string(), record, "a regular file inside the export, not a symbolic link" + listed_by);
    throw IoError(path.string(), record, std::string("cannot open: ") + std::strerror(errno) + listed_by);
  }
  struct stat st {};
  if (::fstat(f.fd, &st) != 0)
    throw IoError(path.string(), record, std::string("cannot stat: ") + std::strerror(errno));
  NSG_CHECK(S_ISREG(st.st_mode), DataError, path.string(), record,
            "a regular file (not a device, FIFO, socket or folder)" + listed_by);
  const int64_t size = static_cast<int64_t>(st.st_size);
  NSG_CHECK(expected_bytes < 0 || size == expected_bytes, DataError, path.string(), record,
            strprintf("the size %lld bytes", static_cast<long long>(expected_bytes)) + listed_by +
                strprintf(", got %lld", static_cast<long long>(size)));
  NSG_CHECK(size <= max_bytes, DataError, path.string(), record,
            strprintf("a file of at most %lld bytes (the format's limit), got %lld", static_cast<long long>(max_bytes),
                      static_cast<long long>(size)));
  std::string out(static_cast<size_t>(size), '\0');
  size_t done = 0;
  while (done < out.size()) {
    const ssize_t n = ::read(f.fd, out.data() + done, out.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw IoError(path.string(), record, std::string("read error: ") + std::strerror(errno));
    NSG_CHECK(n > 0, DataError, path.string(), record,
              strprintf("%lld bytes, as it measured when opened (it shrank while read)", static_cast<long long>(size)));
    done += static_cast<size_t>(n);
  }
  return out;
}

// Every folder between the export and a listed file, checked without following links: a
// link could lead out of the export (the file itself is opened with O_NOFOLLOW).
void require_no_symlinked_folder(const fs::path& export_dir, const std::string& relative,
                                 const std::string& listed_by) {
  fs::path at = export_dir;
  const fs::path rel(relative);
  for (auto part = rel.begin(); part != rel.end() && std::next(part) != rel.end(); ++part) {
    at /= *part;
    std::error_code ec;
    NSG_CHECK(!fs::is_symlink(fs::symlink_status(at, ec)), DataError, (export_dir / relative).string(), relative,
              "a file inside the export: " + at.string() + " is a symbolic link" + listed_by);
  }
}

// --- The manifest (nlohmann: a few MiB, read once) ----------------------------------------

class ManifestReader {
 public:
  explicit ManifestReader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& at, const std::string& expected) const {
    throw ParseError(file_, at, expected);
  }

  const json& member(const json& parent, const std::string& at, const char* key, const std::string& expected) const {
    if (!parent.is_object()) fail(at, "an object");
    const auto it = parent.find(key);
    if (it == parent.end()) fail(at + "/" + key, expected + " (missing)");
    return *it;
  }
  const json& object(const json& parent, const std::string& at, const char* key, const std::string& expected) const {
    const json& v = member(parent, at, key, expected);
    if (!v.is_object()) fail(at + "/" + key, expected);
    return v;
  }
  std::string text(const json& parent, const std::string& at, const char* key, const std::string& expected) const {
    const json& v = member(parent, at, key, expected);
    if (!v.is_string()) fail(at + "/" + key, expected);
    return v.get<std::string>();
  }
  bool boolean(const json& parent, const std::string& at, const char* key, const std::string& expected) const {
    const json& v = member(parent, at, key, expected);
    if (!v.is_boolean()) fail(at + "/" + key, expected);
    return v.get<bool>();
  }
  int64_t integer(const json& parent, const std::string& at, const char* key, int64_t lo, int64_t hi,
                  const std::string& expected) const {
    const json& v = member(parent, at, key, expected);
    // number_unsigned beyond int64 would wrap in get<int64_t>: compared as unsigned first.
    const bool ok = v.is_number_unsigned() ? v.get<uint64_t>() <= static_cast<uint64_t>(hi)
                                           : v.is_number_integer() && v.get<int64_t>() <= hi;
    if (!ok || v.get<int64_t>() < lo) fail(at + "/" + key, expected);
    return v.get<int64_t>();
  }
  double number(const json& parent, const std::string& at, const char* key, double lo, double hi,
                const std::string& expected) const {
    const json& v = member(parent, at, key, expected);
    if (!v.is_number() || !(v.get<double>() >= lo && v.get<double>() <= hi)) fail(at + "/" + key, expected);
    return v.get<double>();
  }

  FramesWindowM window(const json& config) const {
    const json& w = object(config, "/config", "window", "the window {x_min_m, x_max_m, y_min_m, y_max_m}");
    const std::string range = strprintf("metres within ±%g", kWindowLimitM);
    FramesWindowM out;
    out.x_min_m = number(w, "/config/window", "x_min_m", -kWindowLimitM, kWindowLimitM, range);
    out.x_max_m = number(w, "/config/window", "x_max_m", -kWindowLimitM, kWindowLimitM, range);
    out.y_min_m = number(w, "/config/window", "y_min_m", -kWindowLimitM, kWindowLimitM, range);
    out.y_max_m = number(w, "/config/window", "y_max_m", -kWindowLimitM, kWindowLimitM, range);
    if (!(out.x_min_m < out.x_max_m)) fail("/config/window/x_max_m", "greater than x_min_m");
    if (!(out.y_min_m < out.y_max_m)) fail("/config/window/y_max_m", "greater than y_min_m");
    return out;
  }

  FramesListedFile listed(const json& f, const std::string& at) const {
    FramesListedFile out;
    out.path = text(f, at, "path", "the file's path relative to the export");
    // No NUL (a C path would end there) and no backslash (a folder separator elsewhere).
    if (!stays_inside(out.path) || out.path.find_first_of(std::string("\\\0", 2)) != std::string::npos)
      fail(at + "/path", "a path inside the export (relative, no \"..\"), got \"" + out.path + "\"");
    out.bytes = integer(f, at, "bytes", 0, std::numeric_limits<int64_t>::max(), "the file's size, an integer ≥ 0");
    out.sha256 = text(f, at, "sha256", "the file's sha256, 64 lowercase hex digits");
    if (out.sha256.size() != 64 || out.sha256.find_first_not_of("0123456789abcdef") != std::string::npos)
      fail(at + "/sha256", "the file's sha256, 64 lowercase hex digits");
    return out;
  }

  std::vector<FramesListedFile> files(const json& doc, const FramesDocumentLimits& limits) const {
    const json& files = member(doc, "", "files", "the export's files [{path, bytes, sha256}]");
    if (!files.is_array()) fail("/files", "an array of {path, bytes, sha256}");
    if (static_cast<int64_t>(files.size()) > limits.max_manifest_files)
      fail("/files", strprintf("at most %lld files", static_cast<long long>(limits.max_manifest_files)));
    std::vector<FramesListedFile> out;
    out.reserve(files.size());
    std::unordered_set<std::string_view> seen;
    for (size_t i = 0; i < files.size(); ++i) {
      out.push_back(listed(files[i], "/files/" + std::to_string(i)));
      if (!seen.insert(out.back().path).second)
        fail("/files/" + std::to_string(i) + "/path", "each file listed once, got \"" + out.back().path + "\" again");
    }
    return out;
  }

 private:
  std::string file_;
};

// --- The record (simdjson: a split holds tens of thousands) -------------------------------

using simdjson::dom::array;
using simdjson::dom::element;
using simdjson::dom::object;

class RecordReader {
 public:
  RecordReader(const std::string& file, const FramesDocumentLimits& limits) : file_(file), limits_(limits) {}

  FrameRecord read(element doc) const {
    const object top = as_object(doc, "", "a frame record {sample_token, pose, annotation, …}");
    FrameRecord r;
    r.schema_version = text(member(top, "", "schema_version", "\"1\""), "/schema_version", "\"1\"");
    if (r.schema_version != "1") fail("/schema_version", "\"1\" (a version-1 frame record)");
    const std::string versions = std::string("\"") + kFrameRecordVersion + "\" or \"" + kFrameRecordVersion1 + "\"";
    r.version = text(member(top, "", "version", versions), "/version", versions);
    if (r.version != kFrameRecordVersion && r.version != kFrameRecordVersion1) fail("/version", versions);
    r.segment_id = text(member(top, "", "segment_id", "the scene's name"), "/segment_id", "the scene's name", true);
    r.sample_token =
        text(member(top, "", "sample_token", "the sample's token"), "/sample_token", "the sample's token", true);
    r.split = text(member(top, "", "split", "train, val or test"), "/split", "train, val or test");
    if (r.split != "train" && r.split != "val" && r.split != "test") fail("/split", "train, val or test");
    r.timestamp_us = integer(member(top, "", "timestamp", "the sample's timestamp (µs)"), "/timestamp", 0,
                             std::numeric_limits<int64_t>::max(), "the sample's timestamp, an integer ≥ 0 (µs)");
    r.meta_data = meta_data(member(top, "", "meta_data", "the frame's source"));
    r.cameras = cameras(member(top, "", "sensor", "the cameras {channel: …}"));
    r.pose = transform(member(top, "", "pose", "{\"rotation\": 3 x 3, \"translation\": 3}"), "/pose");
    annotation(member(top, "", "annotation", "{lane_centerline, topology_lclc, …}"), r);
    element overlap;
    if (top.at_key("overlap").get(overlap) == simdjson::SUCCESS) r.overlap = boolean(overlap, "/overlap");
    return r;
  }

 private:
  // What was expected is a view (a literal mostly) and pointers below `at` are spelt out only
  // for a defect: a record holds thousands of values, read at GB/s.
  [[noreturn]] void fail(const std::string& at, std::string_view expected) const {
    throw ParseError(file_, at, std::string(expected));
  }
  static std::string below(const std::string& at, size_t index) { return at + "/" + std::to_string(index); }

  element member(object o, const std::string& at, const char* key, std::string_view what) const {
    element out;
    if (o.at_key(key).get(out) != simdjson::SUCCESS) fail(at + "/" + key, std::string(what) + " (missing)");
    return out;
  }
  object as_object(element e, const std::string& at, std::string_view expected) const {
    object out;
    if (e.get_object().get(out) != simdjson::SUCCESS) fail(at, expected);
    return out;
  }
  array as_array(element e, const std::string& at, std::string_view expected) const {
    array out;
    if (e.get_array().get(out) != simdjson::SUCCESS) fail(at, expected);
    return out;
  }
  std::string text(element e, const std::string& at, std::string_view expected, bool non_empty = false) const {
    std::string_view out;
    if (e.get_string().get(out) != simdjson::SUCCESS || (non_empty && out.empty()))
      fail(at, std::string(expected) + (non_empty ? " (a non-empty string)" : " (a string)"));
    return std::string(out);
  }
  bool boolean(element e, const std::string& at) const {
    bool out = false;
    if (e.get_bool().get(out) != simdjson::SUCCESS) fail(at, "true or false");
    return out;
  }
  int64_t integer(element e, const std::string& at, int64_t lo, int64_t hi, std::string_view expected) const {
    int64_t out = 0;
    if (e.get_int64().get(out) != simdjson::SUCCESS || out < lo || out > hi) fail(at, expected);
    return out;
  }
  static bool within(element e, double bound, double* out) {
    const std::optional<double> v = detail::number(e);
    if (!v || !std::isfinite(*v) || std::abs(*v) > bound) return false;
    *out = *v;
    return true;
  }

  std::array<double, 3> triple(element e, const std::string& at, double bound, std::string_view expected) const {
    array a;
    if (e.get_array().get(a) != simdjson::SUCCESS || a.size() != 3) fail(at, expected);
    std::array<double, 3> out{};
    size_t i = 0;
    for (const element v : a) {
      if (!within(v, bound, &out[i])) fail(below(at, i), expected);
      ++i;
    }
    return out;
  }
  std::array<std::array<double, 3>, 3> matrix(element e, const std::string& at, double bound,
                                              const std::string& expected) const {
    const array rows = as_array(e, at, "3 x 3: " + expected);
    if (rows.size() != 3) fail(at, "3 x 3: " + expected);
    std::array<std::array<double, 3>, 3> out{};
    size_t r = 0;
    for (const element row : rows) {
      out[r] = triple(row, at + "/" + std::to_string(r), bound, "3 x 3: " + expected);
      ++r;
    }
    return out;
  }
  FrameTransform transform(element e, const std::string& at) const {
    const object o = as_object(e, at, "{\"rotation\": 3 x 3, \"translation\": 3}");
    FrameTransform t;
    t.rotation = matrix(member(o, at, "rotation", "a 3 x 3 rotation"), at + "/rotation", kMaxRotationEntry,
                        "a rotation's entries, numbers in [-1, 1]");
    t.translation = triple(member(o, at, "translation", "[x, y, z] metres"), at + "/translation",
                           limits_.max_abs_coordinate_m, coordinates());
    return t;
  }
  std::string coordinates() const {
    return strprintf("[x, y, z]: finite numbers within ±%g m", limits_.max_abs_coordinate_m);
  }

  FrameRecord::MetaData meta_data(element e) const {
    const object o = as_object(e, "/meta_data", "{source, source_id, version, location, map_version, region}");
    FrameRecord::MetaData m;
    m.source = text(member(o, "/meta_data", "source", "\"nuscenes\""), "/meta_data/source", "\"nuscenes\"");
    m.source_id =
        text(member(o, "/meta_data", "source_id", "the scene's token"), "/meta_data/source_id", "the scene's token");
    m.version = text(member(o, "/meta_data", "version", "the release's version"), "/meta_data/version",
                     "the release's version");
    m.location = text(member(o, "/meta_data", "location", "the map's location"), "/meta_data/location",
                      "the map's location", true);
    m.map_version = text(member(o, "/meta_data", "map_version", "the map's version"), "/meta_data/map_version",
                         "the map's version");
    const element region = member(o, "/meta_data", "region", "the region's name or null");
    if (!region.is_null()) m.region = text(region, "/meta_data/region", "the region's name or null");
    return m;
  }

  std::vector<FrameCamera> cameras(element e) const {
    const object sensors = as_object(e, "/sensor", "{channel: camera}");
    std::vector<FrameCamera> out;
    for (const auto field : sensors) {
      if (static_cast<int64_t>(out.size()) >= limits_.max_cameras)
        fail("/sensor", strprintf("at most %lld cameras", static_cast<long long>(limits_.max_cameras)));
      const std::string at = "/sensor/" + validate::json_pointer_token(std::string(field.key));
      const object c = as_object(field.value, at, "a camera {image_path, timestamp, width, height, …}");
      FrameCamera cam;
      cam.channel = std::string(field.key);
      cam.image_path =
          text(member(c, at, "image_path", "the image's path"), at + "/image_path", "the image's path", true);
      // Relative to the release or the export, and inside it: a reader joins it to that folder.
      if (!stays_inside(cam.image_path))
        fail(at + "/image_path",
             "a path inside the release or the export (relative, no \"..\"), got \"" + cam.image_path + "\"");
      cam.timestamp_us = integer(member(c, at, "timestamp", "the image's timestamp (µs)"), at + "/timestamp", 0,
                                 std::numeric_limits<int64_t>::max(), "the image's timestamp, an integer ≥ 0 (µs)");
      const std::string side = strprintf("an integer in [0, %lld] (px)", static_cast<long long>(kMaxImageSidePx));
      cam.width = integer(member(c, at, "width", side), at + "/width", 0, kMaxImageSidePx, side);
      cam.height = integer(member(c, at, "height", side), at + "/height", 0, kMaxImageSidePx, side);
      cam.extrinsic = transform(member(c, at, "extrinsic", "camera → ego"), at + "/extrinsic");
      const object intrinsic = as_object(member(c, at, "intrinsic", "{\"K\": 3 x 3, \"distortion\": []}"),
                                         at + "/intrinsic", "{\"K\": 3 x 3, \"distortion\": []}");
      cam.k = matrix(member(intrinsic, at + "/intrinsic", "K", "the camera matrix"), at + "/intrinsic/K",
                     limits_.max_abs_coordinate_m, "the camera matrix's entries, finite numbers (px)");
      cam.ego_pose = transform(member(c, at, "ego_pose", "ego → global"), at + "/ego_pose");
      out.push_back(std::move(cam));
    }
    return out;
  }

  std::vector<Point3> points(element e, const std::string& at) const {
    array a;
    if (e.get_array().get(a) != simdjson::SUCCESS || a.size() < 2 ||
        static_cast<int64_t>(a.size()) > limits_.max_points_per_centerline)
      fail(at, strprintf("2 to %lld points [x, y, z]", static_cast<long long>(limits_.max_points_per_centerline)));
    std::vector<Point3> out(a.size());
    size_t k = 0;
    for (const element p : a) {
      array xyz;
      if (p.get_array().get(xyz) != simdjson::SUCCESS || xyz.size() != 3) fail(below(at, k), coordinates());
      size_t c = 0;
      for (const element x : xyz) {
        if (!within(x, limits_.max_abs_coordinate_m, &out[k][c])) fail(below(below(at, k), c), coordinates());
        ++c;
      }
      ++k;
    }
    return out;
  }

  FrameRecordCenterline centerline(element e, const std::string& at) const {
    const object o = as_object(e, at, "a centerline {id, points, points_2m, …}");
    FrameRecordCenterline c;
    c.id = integer(member(o, at, "id", "the centerline's id"), at + "/id", 0, std::numeric_limits<int64_t>::max(),
                   "the centerline's id, an integer ≥ 0");
    c.points = points(member(o, at, "points", "its points"), at + "/points");
    c.points_2m = points(member(o, at, "points_2m", "its nodes at most 2 m apart"), at + "/points_2m");
    c.is_connector =
        boolean(member(o, at, "is_intersection_or_connector", "true or false"), at + "/is_intersection_or_connector");
    c.lane_token =
        text(member(o, at, "lane_token", "the map lane's token"), at + "/lane_token", "the map lane's token");
    c.starts_at_lane_start =
        boolean(member(o, at, "starts_at_lane_start", "true or false"), at + "/starts_at_lane_start");
    c.ends_at_lane_end = boolean(member(o, at, "ends_at_lane_end", "true or false"), at + "/ends_at_lane_end");
    return c;
  }

  void annotation(element e, FrameRecord& r) const {
    const std::string at = "/annotation";
    const object o = as_object(e, at, "{lane_centerline, traffic_element, topology_lclc, topology_lcte}");
    const array lanes = as_array(member(o, at, "lane_centerline", "the centerlines"), at + "/lane_centerline",
                                 "an array of centerlines");
    if (static_cast<int64_t>(lanes.size()) > limits_.max_centerlines)
      fail(at + "/lane_centerline",
           strprintf("at most %lld centerlines", static_cast<long long>(limits_.max_centerlines)));
    for (const element lane : lanes)
      r.centerlines.push_back(centerline(lane, at + "/lane_centerline/" + std::to_string(r.centerlines.size())));
    const size_t n = r.centerlines.size();
    r.topology_lclc = adjacency(o, at, "topology_lclc", n, "centerline");
    // No traffic elements (nuScenes has none): [] and n × 0.
    if (as_array(member(o, at, "traffic_element", "[]"), at + "/traffic_element", "[] (no traffic elements)").size() !=
        0)
      fail(at + "/traffic_element", "[] (no traffic elements)");
    no_traffic_elements(o, at, "topology_lcte", n);
    if (!r.has_map_elements()) return;
    const std::string segments_shape = std::to_string(n) + " lane segments (one per centerline, in their order)";
    const array segments =
        as_array(member(o, at, "lane_segment", segments_shape), at + "/lane_segment", segments_shape);
    if (segments.size() != n) fail(at + "/lane_segment", segments_shape);
    for (const element e : segments) {
      const std::string here = at + "/lane_segment/" + std::to_string(r.lane_segments.size());
      r.lane_segments.push_back(lane_segment(e, here));
      if (r.lane_segments.back().id != r.centerlines[r.lane_segments.size() - 1].id)
        fail(here + "/id", "the id of the centerline at its position");
    }
    const array areas = as_array(member(o, at, "area", "the areas"), at + "/area", "an array of areas");
    if (static_cast<int64_t>(areas.size()) > limits_.max_centerlines)
      fail(at + "/area", strprintf("at most %lld areas", static_cast<long long>(limits_.max_centerlines)));
    for (const element e : areas) r.areas.push_back(area(e, at + "/area/" + std::to_string(r.areas.size())));
    r.topology_lsls = adjacency(o, at, "topology_lsls", n, "lane segment");
    no_traffic_elements(o, at, "topology_lste", n);
  }

  // An n × n matrix of 0 or 1, row-major.
  std::vector<uint8_t> adjacency(const object& o, const std::string& at, const char* name, size_t n,
                                 const char* row_of) const {
    const std::string shape = std::to_string(n) + " x " + std::to_string(n) + " of 0 or 1 (one row per " + row_of + ")";
    const std::string here = at + "/" + name;
    const array rows = as_array(member(o, at, name, shape), here, shape);
    if (rows.size() != n) fail(here, shape);
    std::vector<uint8_t> out;
    out.reserve(n * n);
    size_t i = 0;
    for (const element row_e : rows) {
      const std::string row_at = here + "/" + std::to_string(i++);
      const array row = as_array(row_e, row_at, shape);
      if (row.size() != n) fail(row_at, shape);
      size_t j = 0;
      for (const element v : row) {
        const std::optional<double> x = detail::number(v);
        if (!x || (*x != 0.0 && *x != 1.0)) fail(row_at + "/" + std::to_string(j), "0 or 1");
        out.push_back(*x == 1.0 ? 1 : 0);
        ++j;
      }
    }
    return out;
  }

  // n × 0: a row per centerline, no traffic element.
  void no_traffic_elements(const object& o, const std::string& at, const char* name, size_t n) const {
    const std::string shape = std::to_string(n) + " x 0 (no traffic elements)";
    const std::string here = at + "/" + name;
    const array rows = as_array(member(o, at, name, shape), here, shape);
    if (rows.size() != n) fail(here, shape);
    size_t k = 0;
    for (const element row : rows)
      if (as_array(row, here + "/" + std::to_string(k++), shape).size() != 0)
        fail(here + "/" + std::to_string(k - 1), shape);
  }

  int line_type(const object& o, const std::string& at, const char* name) const {
    return static_cast<int>(integer(member(o, at, name, "0 (none), 1 (solid) or 2 (dash)"), at + "/" + name, 0, 2,
                                    "0 (none), 1 (solid) or 2 (dash)"));
  }

  FrameRecordLaneSegment lane_segment(element e, const std::string& at) const {
    const object o = as_object(e, at, "a lane segment {id, centerline, left_laneline, right_laneline, …}");
    FrameRecordLaneSegment s;
    s.id = integer(member(o, at, "id", "the lane segment's id"), at + "/id", 0, std::numeric_limits<int64_t>::max(),
                   "the lane segment's id, an integer ≥ 0");
    s.centerline = points(member(o, at, "centerline", "its centerline"), at + "/centerline");
    s.left_laneline = points(member(o, at, "left_laneline", "its left laneline"), at + "/left_laneline");
    s.left_type = line_type(o, at, "left_laneline_type");
    s.right_laneline = points(member(o, at, "right_laneline", "its right laneline"), at + "/right_laneline");
    s.right_type = line_type(o, at, "right_laneline_type");
    s.is_connector =
        boolean(member(o, at, "is_intersection_or_connector", "true or false"), at + "/is_intersection_or_connector");
    return s;
  }

  FrameRecordArea area(element e, const std::string& at) const {
    const object o = as_object(e, at, "an area {id, category, points}");
    FrameRecordArea a;
    a.id = integer(member(o, at, "id", "the area's id"), at + "/id", 0, std::numeric_limits<int64_t>::max(),
                   "the area's id, an integer ≥ 0");
    a.category = static_cast<int>(integer(member(o, at, "category", "1 (pedestrian crossing) or 2 (road boundary)"),
                                          at + "/category", 1, 2, "1 (pedestrian crossing) or 2 (road boundary)"));
    a.points = points(member(o, at, "points", "its points"), at + "/points");
    return a;
  }

  const std::string& file_;
  const FramesDocumentLimits& limits_;
};

}  // namespace

std::filesystem::path FramesManifest::release_folder() const { return resolve_document_path(dataroot, export_dir); }

std::vector<const FramesListedFile*> FramesManifest::records(const std::string& split) const {
  std::vector<const FramesListedFile*> out;
  const std::string prefix = split + "/";
  for (const FramesListedFile& f : files)
    if (f.path.rfind(prefix, 0) == 0 && f.path.find("/info/") != std::string::npos) out.push_back(&f);
  return out;
}

FramesManifest read_frames_manifest(const fs::path& export_dir, const FramesDocumentLimits& limits) {
  FramesManifest m;
  m.export_dir = export_dir;
  m.file = export_dir / "manifest.json";
  std::error_code ec;
  NSG_CHECK(fs::exists(fs::symlink_status(m.file, ec)), IoError, m.file.string(), "",
            "an nsgraph frames export (its manifest.json)");
  // The export's folder is the user's to name (it may be a link); its manifest is still
  // measured, and must be a file, before it is read.
  const std::string text = read_regular_file(m.file, /*no_symlink=*/false, -1, limits.max_manifest_bytes, "", "");
  m.document = parse_json_strict(text, m.file.string(), "an nsgraph frames manifest", limits.max_depth);
  const ManifestReader r(m.file.string());
  const json& doc = m.document;
  if (!doc.is_object()) r.fail("", "an object (the manifest of an `nsgraph frames` export)");
  const auto kind = doc.find("kind");
  if (kind == doc.end() || !kind->is_string() || kind->get<std::string>() != kManifestKind)
    r.fail("/kind", std::string("\"") + kManifestKind + "\" (the manifest of an `nsgraph frames` export)");
  if (r.text(doc, "", "schema_version", "\"1\"") != "1") r.fail("/schema_version", "\"1\" (a version-1 export)");
  const json& source = r.object(doc, "", "source", "the export's source {dataset_manifest_sha256, dataroot, …}");
  m.dataset_manifest_sha256 =
      r.text(source, "/source", "dataset_manifest_sha256", "the dataset manifest's sha256, 64 lowercase hex digits");
  if (m.dataset_manifest_sha256.size() != 64 ||
      m.dataset_manifest_sha256.find_first_not_of("0123456789abcdef") != std::string::npos)
    r.fail("/source/dataset_manifest_sha256", "the dataset manifest's sha256, 64 lowercase hex digits");
  m.dataroot = r.text(source, "/source", "dataroot", "the release's folder (a string)");
  const json& config = r.object(doc, "", "config", "the resolved frames config");
  m.window = r.window(config);
  m.centerline_points = static_cast<int>(r.integer(config, "/config", "centerline_points", 2, kMaxCenterlinePoints,
                                                   strprintf("an integer in [2, %d]", kMaxCenterlinePoints)));
  m.copy_images = r.boolean(config, "/config", "copy_images", "true or false");
  m.files = r.files(doc, limits);
  return m;
}

std::string read_listed_file(const FramesManifest& manifest, const FramesListedFile& listed, int64_t max_bytes,
                             bool verify) {
  // Checked again here: a FramesManifest built by hand has not been through the reader.
  NSG_CHECK(stays_inside(listed.path), DataError, manifest.file.string(), listed.path, "a path inside the export");
  const std::string listed_by = ", as " + manifest.file.string() + " lists it";
  require_no_symlinked_folder(manifest.export_dir, listed.path, listed_by);
  const fs::path file = manifest.export_dir / listed.path;
  std::error_code ec;
  NSG_CHECK(fs::exists(fs::symlink_status(file, ec)), DataError, file.string(), listed.path, "present" + listed_by);
  std::string bytes = read_regular_file(file, /*no_symlink=*/true, listed.bytes, max_bytes, listed.path, listed_by);
  if (verify)
    NSG_CHECK(sha256_hex(bytes) == listed.sha256, DataError, file.string(), listed.path,
              "the sha256 " + manifest.file.string() + " records");
  return bytes;
}

std::string FrameRecord::identifier() const { return split + "/" + segment_id + "/" + std::to_string(timestamp_us); }

namespace {

// read_frame_record with the caller's parser: a split's records reuse one (its buffers).
FrameRecord parse_record(simdjson::dom::parser& parser, std::string_view text, const std::string& file,
                         const FramesDocumentLimits& limits) {
  NSG_CHECK(static_cast<int64_t>(text.size()) <= limits.max_record_bytes, ParseError, file, "",
            strprintf("a frame record of at most %lld bytes", static_cast<long long>(limits.max_record_bytes)));
  const simdjson::padded_string padded(text);
  element doc;
  Issues issues;
  if (!detail::parse_strict(parser, padded, file, limits.max_depth, limits.max_json_values, doc, issues)) {
    // The strict parse names its problem "<file>:<pointer>"; the record's reader throws it.
    const Issue& first = issues.items().front();
    const std::string pointer = first.subject.size() > file.size() ? first.subject.substr(file.size() + 1) : "";
    const std::string said = first.message.rfind("expected ", 0) == 0 ? first.message.substr(9) : first.message;
    throw ParseError(file, pointer, said + " (a frame record)");
  }
  return RecordReader(file, limits).read(doc);
}

FrameRecord read_listed_record_with(simdjson::dom::parser& parser, const FramesManifest& manifest,
                                    const FramesListedFile& listed, bool verify, const FramesDocumentLimits& limits) {
  const std::string text = read_listed_file(manifest, listed, limits.max_record_bytes, verify);
  const std::string file = (manifest.export_dir / listed.path).string();
  FrameRecord record = parse_record(parser, text, file, limits);
  const std::string folder = listed.path.substr(0, listed.path.find('/'));
  NSG_CHECK(record.split == folder, DataError, file, "/split",
            "\"" + folder + "\", the split its path " + listed.path + " lies in");
  return record;
}

}  // namespace

FrameRecord read_frame_record(std::string_view text, const std::string& file, const FramesDocumentLimits& limits) {
  simdjson::dom::parser parser;
  return parse_record(parser, text, file, limits);
}

FrameRecord read_listed_record(const FramesManifest& manifest, const FramesListedFile& listed, bool verify,
                               const FramesDocumentLimits& limits) {
  simdjson::dom::parser parser;
  return read_listed_record_with(parser, manifest, listed, verify, limits);
}

void for_each_frame_record(const FramesManifest& manifest, const std::string& split, bool verify,
                           const std::function<void(const FrameRecord&, const FramesListedFile&)>& fn,
                           const FramesDocumentLimits& limits) {
  simdjson::dom::parser parser;
  for (const FramesListedFile* listed : manifest.records(split))
    fn(read_listed_record_with(parser, manifest, *listed, verify, limits), *listed);
}

}  // namespace nsg::metrics

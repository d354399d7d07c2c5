// `nsgraph frames render` (nsg/frames/render.h): projection by the devkit's chain, drawing
// with OpenCV, every file through the output folder's one owner.
#include "nsg/frames/render.h"

#include <cmath>
#include <map>
#include <set>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "nsg/core/bounded_file.h"
#include "nsg/core/error.h"
#include "nsg/core/output_folder.h"
#include "nsg/core/strings.h"
#include "nsg/metrics/frames.h"
#include "nsg/nuscenes/camera.h"

namespace nsg::frames {
namespace {

namespace fs = std::filesystem;
using metrics::FrameCamera;
using metrics::FrameRecord;
using metrics::FrameTransform;
using metrics::Point3;

// R · p + t, and its inverse Rᵀ · (p − t).
Point3 apply(const FrameTransform& T, const Point3& p) {
  Point3 out{};
  for (int r = 0; r < 3; ++r)
    out[r] = T.rotation[r][0] * p[0] + T.rotation[r][1] * p[1] + T.rotation[r][2] * p[2] + T.translation[r];
  return out;
}
Point3 apply_inverse(const FrameTransform& T, const Point3& p) {
  const Point3 d = {p[0] - T.translation[0], p[1] - T.translation[1], p[2] - T.translation[2]};
  Point3 out{};
  for (int c = 0; c < 3; ++c) out[c] = T.rotation[0][c] * d[0] + T.rotation[1][c] * d[1] + T.rotation[2][c] * d[2];
  return out;
}

// The point in the camera frame (x right, y down, z forward).
Point3 in_camera(const FrameRecord& record, const FrameCamera& camera, const Point3& ego_point) {
  const Point3 global = apply(record.pose, ego_point);
  return apply_inverse(camera.extrinsic, apply_inverse(camera.ego_pose, global));
}

ImagePoint to_pixels(const FrameCamera& camera, const Point3& c) {
  const auto& K = camera.k;
  const double x = K[0][0] * c[0] + K[0][1] * c[1] + K[0][2] * c[2];
  const double y = K[1][0] * c[0] + K[1][1] * c[1] + K[1][2] * c[2];
  const double w = K[2][0] * c[0] + K[2][1] * c[1] + K[2][2] * c[2];
  return {x / w, y / w, c[2]};
}

// RGB colours: the ground truth green, a submission magenta; a version-2 record's lanelines
// pale green, its pedestrian crossings cyan and road boundaries orange.
const cv::Scalar kTruthRgb(40, 220, 60);
const cv::Scalar kPredictionRgb(235, 40, 220);
const cv::Scalar kLanelineRgb(170, 235, 170);
const cv::Scalar kCrossingRgb(40, 210, 230);
const cv::Scalar kBoundaryRgb(245, 150, 30);

struct Layer {
  const std::vector<std::vector<Point3>>* lanes;
  cv::Scalar rgb;
  int thickness;
  bool arrow = true;  // an arrowhead on the last segment: a lane's direction
};

// A polyline, with an arrowhead on its last segment when `arrow` (the lane's direction).
void draw_polyline(cv::Mat& image, const std::vector<cv::Point2d>& points, const cv::Scalar& rgb, int thickness,
                   bool arrow = true) {
  constexpr int kShift = 4;  // sub-pixel coordinates: 1/16 px
  const auto fixed = [](const cv::Point2d& p) {
    return cv::Point(static_cast<int>(std::lround(p.x * (1 << kShift))),
                     static_cast<int>(std::lround(p.y * (1 << kShift))));
  };
  for (size_t i = 1; i < points.size(); ++i) {
    if (arrow && i + 1 == points.size())
      cv::arrowedLine(image, fixed(points[i - 1]), fixed(points[i]), rgb, thickness, cv::LINE_AA, kShift, 0.3);
    else cv::line(image, fixed(points[i - 1]), fixed(points[i]), rgb, thickness, cv::LINE_AA, kShift);
  }
}

bool inside(const ImagePoint& p, const FrameCamera& camera) {
  return p.u >= 0 && p.v >= 0 && p.u < static_cast<double>(camera.width) && p.v < static_cast<double>(camera.height);
}

// The camera image with every layer's centerlines drawn; returns the pieces of the first layer
// with a point inside the image.
int draw_camera(cv::Mat& rgb, const FrameRecord& record, const FrameCamera& camera, const std::vector<Layer>& layers) {
  int truth_pieces = 0;
  for (size_t l = 0; l < layers.size(); ++l)
    for (const auto& lane : *layers[l].lanes)
      for (const std::vector<ImagePoint>& piece : project_polyline(record, camera, lane)) {
        std::vector<cv::Point2d> pts;
        bool seen = false;
        for (const ImagePoint& p : piece) {
          pts.emplace_back(p.u, p.v);
          seen = seen || inside(p, camera);
        }
        if (l == 0 && seen) ++truth_pieces;
        draw_polyline(rgb, pts, layers[l].rgb, layers[l].thickness, layers[l].arrow);
      }
  return truth_pieces;
}

// The window from above: x forward is up, y left is left; a 10 m grid and the ego.
cv::Mat draw_bev(const metrics::FramesWindowM& w, double px_per_m, const std::vector<Layer>& layers) {
  const int rows = static_cast<int>(std::ceil((w.x_max_m - w.x_min_m) * px_per_m));
  const int cols = static_cast<int>(std::ceil((w.y_max_m - w.y_min_m) * px_per_m));
  NSG_CHECK(rows > 0 && cols > 0 && static_cast<int64_t>(rows) * cols <= int64_t{64} << 20, ConfigError, "",
            "--bev-px-per-m", "a panel of at most 64 Mpx for the export's window");
  cv::Mat bev(rows, cols, CV_8UC3, cv::Scalar(24, 24, 24));
  const auto at = [&](double x, double y) {
    return cv::Point2d((w.y_max_m - y) * px_per_m, (w.x_max_m - x) * px_per_m);
  };
  for (double x = std::ceil(w.x_min_m / 10) * 10; x <= w.x_max_m; x += 10)
    cv::line(bev, at(x, w.y_min_m), at(x, w.y_max_m), cv::Scalar(60, 60, 60), 1);
  for (double y = std::ceil(w.y_min_m / 10) * 10; y <= w.y_max_m; y += 10)
    cv::line(bev, at(w.x_min_m, y), at(w.x_max_m, y), cv::Scalar(60, 60, 60), 1);
  for (const Layer& layer : layers)
    for (const auto& lane : *layer.lanes) {
      std::vector<cv::Point2d> pts;
      for (const Point3& p : lane) pts.push_back(at(p[0], p[1]));
      draw_polyline(bev, pts, layer.rgb, layer.thickness, layer.arrow);
    }
  const std::vector<cv::Point> ego = {at(2.0, 0.0), at(-1.5, 1.0), at(-1.5, -1.0)};
  cv::fillConvexPoly(bev, ego, cv::Scalar(255, 255, 255), cv::LINE_AA);
  return bev;
}

std::string encode(const cv::Mat& rgb, const char* ext) {
  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  std::vector<uchar> bytes;
  const std::vector<int> params =
      std::string(ext) == ".jpg" ? std::vector<int>{cv::IMWRITE_JPEG_QUALITY, 90} : std::vector<int>{};
  NSG_CHECK(cv::imencode(ext, bgr, bytes, params), InternalError, "", ext, "OpenCV to encode the image");
  return std::string(bytes.begin(), bytes.end());
}

// The frame's record: by its path when named as an identifier (one record read), else the
// split's records in turn until its token.
FrameRecord find_record(const metrics::FramesManifest& manifest, const RenderRequest& request) {
  const std::vector<const metrics::FramesListedFile*> listed = manifest.records(request.split);
  const size_t last_slash = request.frame.rfind('/');
  if (last_slash != std::string::npos) {
    const std::string path =
        request.frame.substr(0, last_slash) + "/info/" + request.frame.substr(last_slash + 1) + ".json";
    for (const metrics::FramesListedFile* f : listed)
      if (f->path == path) return metrics::read_listed_record(manifest, *f, request.verify);
  } else {
    for (const metrics::FramesListedFile* f : listed) {
      FrameRecord r = metrics::read_listed_record(manifest, *f, request.verify);
      if (r.sample_token == request.frame) return r;
    }
  }
  throw ConfigError(manifest.file.string(), "--frame",
                    "a sample token or split/segment_id/timestamp of a frame of split " + request.split + " (\"" +
                        printable_text(request.frame) + "\" is none)");
}

// The submission's centerlines of the frame (empty when it has none).
std::vector<std::vector<Point3>> predicted_lanes(const fs::path& submission, const FrameRecord& record) {
  Issues issues;
  std::optional<metrics::FrameSet> predictions =
      metrics::read_frames_results(submission, metrics::FrameResultsLimits{}, issues);
  if (predictions)
    metrics::key_results_by_token(*predictions, {{record.identifier(), record.sample_token}}, submission.string(),
                                  issues);
  NSG_CHECK(issues.empty(), DataError, submission.string(), "--submission",
            "a results file without problems:\n" + issues.format());
  for (const auto& [key, frame] : *predictions)
    if (key == record.sample_token) return frame.lanes;
  return {};
}

// An earlier render of ours in `out` lists its files in render.json; only those are replaced.
void prepare_out(const OutputFolder& folder, bool overwrite) {
  std::error_code ec;
  if (!fs::exists(folder.root(), ec) || fs::is_empty(folder.root(), ec)) return;
  NSG_CHECK(overwrite, ConfigError, folder.root().string(), "--out",
            "an empty folder (it holds files; --overwrite replaces an earlier render of ours)");
  std::set<std::string> listed;
  try {
    const nlohmann::json doc = nlohmann::json::parse(
        read_file_within(folder.path("render.json"), int64_t{1} << 20, "render.json of nsgraph frames render"));
    if (doc.value("kind", "") == "nsgraph-frames-render" && doc.contains("files") && doc["files"].is_array())
      for (const auto& f : doc["files"])
        if (f.is_string()) listed.insert(f.get<std::string>());
  } catch (const std::exception&) {
    // Not ours: it lists nothing, so the folder's files are refused, not removed.
  }
  folder.remove_listed(listed, {"."}, "render.json of an earlier nsgraph frames render");
}

}  // namespace

ImagePoint project_to_image(const FrameRecord& record, const FrameCamera& camera, const Point3& ego_point) {
  return to_pixels(camera, in_camera(record, camera, ego_point));
}

std::vector<std::vector<ImagePoint>> project_polyline(const FrameRecord& record, const FrameCamera& camera,
                                                      const std::vector<Point3>& ego_points) {
  std::vector<std::vector<ImagePoint>> pieces;
  std::vector<ImagePoint> piece;
  std::optional<Point3> previous;
  for (const Point3& p : ego_points) {
    const Point3 c = in_camera(record, camera, p);
    const bool in_front = c[2] >= kRenderNearM;
    if (previous) {
      const Point3& a = *previous;
      const bool was_in_front = a[2] >= kRenderNearM;
      if (in_front != was_in_front) {  // the segment crosses the near plane: cut it there
        const double t = (kRenderNearM - a[2]) / (c[2] - a[2]);
        const Point3 cut = {a[0] + t * (c[0] - a[0]), a[1] + t * (c[1] - a[1]), kRenderNearM};
        piece.push_back(to_pixels(camera, cut));
        if (!in_front) {
          pieces.push_back(std::move(piece));
          piece.clear();
        }
      }
    }
    if (in_front) piece.push_back(to_pixels(camera, c));
    previous = c;
  }
  pieces.push_back(std::move(piece));
  std::erase_if(pieces, [](const std::vector<ImagePoint>& q) { return q.size() < 2; });  // a point is no line
  return pieces;
}

RenderedFrame render_frame(const RenderRequest& request) {
  NSG_CHECK(!request.out.empty(), ConfigError, "", "--out", "an output folder");
  NSG_CHECK(request.bev_px_per_m > 0 && request.bev_px_per_m <= 100, ConfigError, "", "--bev-px-per-m",
            "pixels per metre in (0, 100]");
  const metrics::FramesManifest manifest = metrics::read_frames_manifest(request.export_dir);
  refuse_out_over_input(request.out, request.export_dir, "--export");
  const FrameRecord record = find_record(manifest, request);
  std::vector<std::vector<Point3>> truth, lanelines, crossings, boundaries;
  for (const auto& c : record.centerlines) truth.push_back(c.points);
  for (const auto& s : record.lane_segments) {  // version 2
    lanelines.push_back(s.left_laneline);
    lanelines.push_back(s.right_laneline);
  }
  for (const auto& a : record.areas) (a.category == 1 ? crossings : boundaries).push_back(a.points);
  const std::vector<std::vector<Point3>> predicted =
      request.submission.empty() ? std::vector<std::vector<Point3>>{} : predicted_lanes(request.submission, record);
  // The ground truth's centerlines first (their pieces in view are counted), the submission's
  // last (drawn over everything).
  const std::vector<Layer> layers = {{&truth, kTruthRgb, 3},
                                     {&boundaries, kBoundaryRgb, 2, false},
                                     {&crossings, kCrossingRgb, 2, false},
                                     {&lanelines, kLanelineRgb, 1, false},
                                     {&predicted, kPredictionRgb, 2}};

  const OutputFolder folder(request.out);
  prepare_out(folder, request.overwrite);
  RenderedFrame out;
  out.sample_token = record.sample_token;
  const fs::path image_root = manifest.copy_images ? manifest.export_dir : manifest.release_folder();
  nuscenes::JpegDecoder decoder;
  for (const FrameCamera& camera : record.cameras) {
    const std::string& channel =
        safe_name(camera.channel, manifest.file.string(), "sensor channel of " + record.sample_token);
    nuscenes::RgbImage image = decoder.decode_file(image_root / camera.image_path);
    NSG_CHECK(image.width == camera.width && image.height == camera.height, DataError,
              (image_root / camera.image_path).string(), channel,
              strprintf("an image of the record's %lld × %lld px", static_cast<long long>(camera.width),
                        static_cast<long long>(camera.height)));
    cv::Mat rgb(image.height, image.width, CV_8UC3, image.pixels.data());
    out.truth_pieces_per_camera.emplace_back(channel, draw_camera(rgb, record, camera, layers));
    folder.write(channel + ".jpg", encode(rgb, ".jpg"));
    out.files.push_back(channel + ".jpg");
  }
  folder.write("bev.png", encode(draw_bev(manifest.window, request.bev_px_per_m, layers), ".png"));
  out.files.push_back("bev.png");
  out.files.push_back("render.json");
  nlohmann::ordered_json drawn = nlohmann::ordered_json::object();
  for (const auto& [channel, n] : out.truth_pieces_per_camera) drawn[channel] = n;
  const nlohmann::ordered_json doc = {{"kind", "nsgraph-frames-render"},
                                      {"sample_token", record.sample_token},
                                      {"identifier", record.identifier()},
                                      {"ground_truth_centerlines", truth.size()},
                                      {"predicted_centerlines", predicted.size()},
                                      {"ground_truth_lanelines", lanelines.size()},
                                      {"ground_truth_areas", crossings.size() + boundaries.size()},
                                      {"truth_pieces_in_image", drawn},
                                      {"files", out.files}};
  folder.write("render.json", doc.dump(1) + "\n");
  return out;
}

}  // namespace nsg::frames

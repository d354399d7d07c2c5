#pragma once
// `nsgraph frames render`: one frame of an export drawn the way a per-frame user first checks
// it — its centerlines projected into each of its camera images (the devkit's chain: ego at
// the LIDAR_TOP key frame → global → the camera's own ego pose → camera → K), and a bird's-eye
// panel of the window; a submission's centerlines beside the ground truth's (docs/frames.md
// "Looking at a frame").
#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "nsg/metrics/frames_documents.h"

namespace nsg::frames {

// Points nearer than this to the camera plane are not drawn (the devkit's min_dist).
inline constexpr double kRenderNearM = 1.0;

struct ImagePoint {
  double u = 0.0;  // pixels, right
  double v = 0.0;  // pixels, down
  double depth_m = 0.0;
};

// A point of the record's ego frame in `camera`'s image: the devkit's chain, depth along the
// optical axis. The point may lie outside the image or behind the camera (depth ≤ 0).
ImagePoint project_to_image(const metrics::FrameRecord& record, const metrics::FrameCamera& camera,
                            const std::array<double, 3>& ego_point);

// A centerline's pieces in front of the camera (depth ≥ kRenderNearM), each cut where it
// crosses that plane, as image points.
std::vector<std::vector<ImagePoint>> project_polyline(const metrics::FrameRecord& record,
                                                      const metrics::FrameCamera& camera,
                                                      const std::vector<metrics::Point3>& ego_points);

struct RenderRequest {
  std::filesystem::path export_dir;
  std::string split = "test";
  std::string frame;                 // a sample token or "split/segment_id/timestamp"
  std::filesystem::path submission;  // "" = the ground truth alone
  std::filesystem::path out;
  bool overwrite = false;  // replace an earlier render (only the files its render.json lists)
  bool verify = true;      // the record's sha256 against the manifest
  double bev_px_per_m = 10.0;
};

struct RenderedFrame {
  std::string sample_token;
  std::vector<std::string> files;  // relative to out: <CHANNEL>.jpg …, bev.png, render.json
  // Per camera, the ground-truth centerline pieces drawn (inside the image, in front).
  std::vector<std::pair<std::string, int>> truth_pieces_per_camera;
};

// Draws the frame: ConfigError / IoError / ParseError / DataError naming the file, the key or
// the option; a submission with problems is a DataError naming its issues. `out` is an empty
// folder or holds an earlier render of ours (replaced with `overwrite`).
RenderedFrame render_frame(const RenderRequest& request);

}  // namespace nsg::frames

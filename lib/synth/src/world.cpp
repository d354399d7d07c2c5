// The synthetic city: street grid + ring road, lanes/connectors, ground raster, buildings.
// Map records are collected by MapBuilder (map_builder.h) while the geometry is made.
#include "nsg/synth/world.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>

#include "map_builder.h"
#include "nsg/core/error.h"
#include "nsg/core/rng.h"
#include "nsg/core/strings.h"
#include "road_geometry.h"

namespace nsg::synth {

using geometry::ArclinePath;
using geometry::ArclineShape;
using geometry::Pose2;

namespace {

constexpr double kPi = 3.141592653589793;
constexpr double kCurbWidthM = 0.3;
constexpr double kParkingWidthM = 2.5;
constexpr double kCrosswalkDepthM = 4.0;  // between the intersection box and the stop line
constexpr double kStraightRadiusM = 999.999;

// ---------------------------------------------------------------------------------------
// Streets, pieces, intersections.

struct Street {
  int n_fwd = 1;
  int n_bwd = 1;  // 0 = one-way
  bool parking = false;
  double lane_w = 3.5;
  bool two_way() const { return n_bwd > 0; }
};

// Lateral layout of a street in its reference frame (left positive, forward direction).
struct StreetLayout {
  std::vector<double> fwd_offsets;  // index 0 = innermost (farthest from the curb side)
  std::vector<double> bwd_offsets;  // in the reference frame
  double left_edge = 0.0;           // road edges (curb lines)
  double right_edge = 0.0;
  double fwd_inner = 0.0, fwd_outer = 0.0;  // lateral span of the forward lanes (inner → curb side)
  double bwd_inner = 0.0, bwd_outer = 0.0;
};

StreetLayout layout_of(const Street& s, bool rht) {
  StreetLayout l;
  const double w = s.lane_w;
  const double park = s.parking ? kParkingWidthM : 0.0;
  // `side` = +1 when the forward lanes are on the left of the reference line.
  if (s.two_way()) {
    const double side = rht ? -1.0 : 1.0;
    for (int k = 0; k < s.n_fwd; ++k) l.fwd_offsets.push_back(side * (k + 0.5) * w);
    for (int k = 0; k < s.n_bwd; ++k) l.bwd_offsets.push_back(-side * (k + 0.5) * w);
    l.fwd_inner = 0.0;
    l.fwd_outer = side * s.n_fwd * w;
    l.bwd_inner = 0.0;
    l.bwd_outer = -side * s.n_bwd * w;
    const double fwd_edge = side * (s.n_fwd * w + park);
    const double bwd_edge = -side * (s.n_bwd * w + park);
    l.left_edge = std::max(fwd_edge, bwd_edge);
    l.right_edge = std::min(fwd_edge, bwd_edge);
  } else {
    const double n = s.n_fwd;
    // Curb side: right for right-hand traffic. Innermost = farthest from it.
    const double curb = rht ? -1.0 : 1.0;
    for (int k = 0; k < s.n_fwd; ++k) l.fwd_offsets.push_back(-curb * (n / 2.0 - k - 0.5) * w);
    l.fwd_inner = -curb * n / 2.0 * w;
    l.fwd_outer = curb * n / 2.0 * w;
    l.left_edge = n / 2.0 * w + park;
    l.right_edge = -(n / 2.0 * w + park);
  }
  return l;
}

struct Piece {
  int street = 0;
  int node_a = -1;  // intersection at the start / end
  int node_b = -1;
  std::vector<Prim> prims;
  double ext_a = 0.0;  // distance from node centre to the piece start (= box half + crosswalk)
  double ext_b = 0.0;
  double length() const {
    double l = 0.0;
    for (const Prim& p : prims) l += p.length;
    return l;
  }
};

struct Intersection {
  Eigen::Vector2d centre;
  double half_m = 0.0;  // half-size of the square box
  int arms = 0;
  std::string segment_token;
};

// A lane as built, before connectors.
struct LaneBuild {
  int piece = 0;
  bool forward = true;
  int index = 0;  // 0 = innermost
  int group_size = 1;
  int start_node = -1, end_node = -1;
  double offset_ref = 0.0;  // in the reference frame
  std::string road_block;
};

// Maps a reference-frame position (s along the piece, d left) to a point, across prims.
Eigen::Vector2d piece_point(const Piece& piece, double s, double d) {
  double rest = s;
  for (size_t i = 0; i < piece.prims.size(); ++i) {
    const Prim& p = piece.prims[i];
    if (rest <= p.length || i + 1 == piece.prims.size()) return prim_point(p, rest, d);
    rest -= p.length;
  }
  return prim_point(piece.prims.back(), rest, d);
}

// Points along the piece at lateral offset d from s0 to s1, evenly spaced ≤ step apart.
std::vector<Eigen::Vector2d> piece_curve(const Piece& piece, double s0, double s1, double d, double step) {
  std::vector<Eigen::Vector2d> out;
  const int n = std::max(1, static_cast<int>(std::ceil((s1 - s0) / step)));
  for (int i = 0; i <= n; ++i) out.push_back(piece_point(piece, s0 + (s1 - s0) * i / n, d));
  return out;
}

ArclinePath straight_path(const Pose2& start, double length, Rng& rng) {
  ArclinePath path;
  path.start_pose = start;
  path.radius_m = kStraightRadiusM;
  // Like real maps: near-straight paths as LSR/RSL with short arcs that cancel.
  const double arc = std::min(rng.uniform(0.0, 0.05), length / 4.0);
  path.shape = rng.bernoulli(0.5) ? ArclineShape::kLSR : ArclineShape::kRSL;
  path.segment_length_m = {arc, length - 2.0 * arc, arc};
  path.end_pose = geometry::arcline_pose_at(path, path.length_m());
  return path;
}

ArclinePath arc_path(const Pose2& start, double length, double curvature) {
  ArclinePath path;
  path.start_pose = start;
  path.radius_m = 1.0 / std::fabs(curvature);
  path.shape = curvature > 0 ? ArclineShape::kLSL : ArclineShape::kRSR;
  path.segment_length_m = {length, 0.0, 0.0};
  path.end_pose = geometry::arcline_pose_at(path, path.length_m());
  return path;
}

Pose2 lane_end_pose(const LaneInfo& lane) {
  const ArclinePath& last = lane.paths.back();
  return geometry::arcline_pose_at(last, last.length_m());
}

double lane_length(const std::vector<ArclinePath>& paths) {
  double l = 0.0;
  for (const auto& p : paths) l += p.length_m();
  return l;
}

}  // namespace

// ---------------------------------------------------------------------------------------
// Dubins (CSC words) for lane connectors.

ArclinePath dubins_path(const Pose2& from, const Pose2& to, double radius_m) {
  auto mod2pi = [](double a) {
    double r = std::fmod(a, 2.0 * kPi);
    if (r < 0) r += 2.0 * kPi;
    if (r > 2.0 * kPi - 1e-9) r = 0.0;  // rounding of a zero turn
    return r;
  };
  const double dx = to.x - from.x, dy = to.y - from.y;
  const double d = std::hypot(dx, dy) / radius_m;
  const double theta = mod2pi(std::atan2(dy, dx));
  const double a = mod2pi(from.yaw - theta), b = mod2pi(to.yaw - theta);
  const double sa = std::sin(a), sb = std::sin(b), ca = std::cos(a), cb = std::cos(b);
  const double cab = std::cos(a - b);
  struct Cand {
    ArclineShape shape;
    double t, p, q;
    bool ok;
  };
  std::vector<Cand> c;
  {  // LSL
    const double p2 = 2 + d * d - 2 * cab + 2 * d * (sa - sb);
    const double tmp = std::atan2(cb - ca, d + sa - sb);
    c.push_back({ArclineShape::kLSL, mod2pi(-a + tmp), std::sqrt(std::max(0.0, p2)), mod2pi(b - tmp), p2 >= 0});
  }
  {  // RSR
    const double p2 = 2 + d * d - 2 * cab + 2 * d * (sb - sa);
    const double tmp = std::atan2(ca - cb, d - sa + sb);
    c.push_back({ArclineShape::kRSR, mod2pi(a - tmp), std::sqrt(std::max(0.0, p2)), mod2pi(-b + tmp), p2 >= 0});
  }
  {  // LSR
    const double p2 = -2 + d * d + 2 * cab + 2 * d * (sa + sb);
    const double p = std::sqrt(std::max(0.0, p2));
    const double tmp = std::atan2(-ca - cb, d + sa + sb) - std::atan2(-2.0, p);
    c.push_back({ArclineShape::kLSR, mod2pi(-a + tmp), p, mod2pi(-b + tmp), p2 >= 0});
  }
  {  // RSL
    const double p2 = -2 + d * d + 2 * cab - 2 * d * (sa + sb);
    const double p = std::sqrt(std::max(0.0, p2));
    const double tmp = std::atan2(ca + cb, d - sa - sb) - std::atan2(2.0, p);
    c.push_back({ArclineShape::kRSL, mod2pi(a - tmp), p, mod2pi(b - tmp), p2 >= 0});
  }
  const Cand* best = nullptr;
  for (const Cand& k : c) {
    if (!k.ok) continue;
    if (!best || k.t + k.p + k.q < best->t + best->p + best->q) best = &k;
  }
  if (!best) throw InternalError("", "dubins", "no CSC Dubins path between the lane ends");
  ArclinePath path;
  path.start_pose = from;
  path.shape = best->shape;
  path.radius_m = radius_m;
  path.segment_length_m = {best->t * radius_m, best->p * radius_m, best->q * radius_m};
  path.end_pose = geometry::arcline_pose_at(path, path.length_m());
  return path;
}

std::vector<Pose2> lane_polyline(const LaneInfo& lane, double step_m) {
  std::vector<Pose2> out;
  for (const ArclinePath& path : lane.paths) {
    std::vector<Pose2> poses = geometry::discretize_arcline(path, step_m);
    size_t first = out.empty() ? 0 : 1;
    out.insert(out.end(), poses.begin() + static_cast<long>(first), poses.end());
  }
  return out;
}

// ---------------------------------------------------------------------------------------
// Ground raster.

GroundRaster::GroundRaster(double x0_m, double y0_m, double resolution_m, int width, int height)
    : x0_(x0_m),
      y0_(y0_m),
      res_(resolution_m),
      width_(width),
      height_(height),
      cells_(static_cast<size_t>(width) * height, static_cast<uint8_t>(GroundMaterial::kTerrain)) {}

GroundMaterial GroundRaster::material(double x_m, double y_m) const {
  const double cx = std::floor((x_m - x0_) / res_), cy = std::floor((y_m - y0_) / res_);
  if (!(cx >= 0 && cy >= 0 && cx < width_ && cy < height_)) return GroundMaterial::kTerrain;
  return static_cast<GroundMaterial>(cells_[static_cast<size_t>(cy) * width_ + static_cast<size_t>(cx)]);
}

GroundSample GroundRaster::sample(double x_m, double y_m) const {
  const GroundMaterial m = material(x_m, y_m);
  return {m, material_height_m(m)};
}

double material_height_m(GroundMaterial m) {
  return (m == GroundMaterial::kSidewalk || m == GroundMaterial::kCurbTop) ? 0.15 : 0.0;
}

bool is_drivable_material(GroundMaterial m) {
  return m == GroundMaterial::kAsphalt || m == GroundMaterial::kPaintWhite || m == GroundMaterial::kPaintYellow ||
         m == GroundMaterial::kCrosswalkPaint;
}

GroundFunction World::ground_function() const {
  std::shared_ptr<const GroundRaster> raster = ground;
  return [raster](double x, double y) { return raster->sample(x, y); };
}

SceneSnapshot World::snapshot(std::vector<SceneBox> dynamic_boxes) const {
  SceneSnapshot s;
  s.ground = ground_function();
  s.static_boxes = buildings;
  s.dynamic_boxes = std::move(dynamic_boxes);
  s.poles = poles;
  s.bounds_m = bounds_m;
  return s;
}

namespace {

// Fills raster cells whose (s, d) in `prim` lie in [s0, s1] × [d0, d1] and pass `keep`.
void paint_band(GroundRaster& r, const Prim& prim, double s0, double s1, double d0, double d1, GroundMaterial m,
                const std::function<bool(double, double)>& keep = nullptr) {
  if (s1 <= s0 || d1 <= d0) return;
  double xmin = 1e300, ymin = 1e300, xmax = -1e300, ymax = -1e300;
  const int n = std::max(2, static_cast<int>((s1 - s0) / 2.0) + 2);
  for (int i = 0; i <= n; ++i) {
    const double s = s0 + (s1 - s0) * i / n;
    for (double d : {d0, d1}) {
      const Eigen::Vector2d p = prim_point(prim, s, d);
      xmin = std::min(xmin, p.x()), xmax = std::max(xmax, p.x());
      ymin = std::min(ymin, p.y()), ymax = std::max(ymax, p.y());
    }
  }
  const double pad = 1.0;  // arcs bulge between samples
  const int c0 = std::max(0, static_cast<int>(std::floor((xmin - pad - r.x0()) / r.resolution())));
  const int c1 = std::min(r.width() - 1, static_cast<int>(std::floor((xmax + pad - r.x0()) / r.resolution())));
  const int r0 = std::max(0, static_cast<int>(std::floor((ymin - pad - r.y0()) / r.resolution())));
  const int r1 = std::min(r.height() - 1, static_cast<int>(std::floor((ymax + pad - r.y0()) / r.resolution())));
  for (int row = r0; row <= r1; ++row) {
    const double y = r.y0() + (row + 0.5) * r.resolution();
    for (int col = c0; col <= c1; ++col) {
      const double x = r.x0() + (col + 0.5) * r.resolution();
      const Eigen::Vector2d sd = prim_local(prim, {x, y});
      if (sd.x() < s0 || sd.x() > s1 || sd.y() < d0 || sd.y() > d1) continue;
      if (keep && !keep(sd.x(), sd.y())) continue;
      r.at(col, row) = static_cast<uint8_t>(m);
    }
  }
}

// The prims of a piece with s ranges, the first/last (straight) extended to node centres.
struct DrawPrim {
  Prim prim;
  double s0, s1;
  double s_offset;  // piece-level s at prim s = 0
};
std::vector<DrawPrim> draw_prims(const Piece& piece) {
  std::vector<DrawPrim> out;
  double acc = 0.0;
  for (size_t i = 0; i < piece.prims.size(); ++i) {
    const Prim& p = piece.prims[i];
    DrawPrim dp{p, 0.0, p.length, acc};
    if (i == 0) dp.s0 = -piece.ext_a;
    if (i + 1 == piece.prims.size()) dp.s1 = p.length + piece.ext_b;
    out.push_back(dp);
    acc += p.length;
  }
  return out;
}

class WorldBuilder {
 public:
  WorldBuilder(const SynthConfig& config, uint64_t seed)
      : cfg_(config),
        city_(config.city),
        rht_(config.right_hand_traffic()),
        rng_(seed, 0x77'6f'72'6c'64),
        map_(Rng(seed, 0x6d'61'70)) {
    world_.config = config;
  }

  World build() {
    make_streets();
    make_pieces();
    make_lanes();
    make_connectors();
    make_ground();
    make_map_areas();
    make_buildings_and_poles();
    make_parking_and_sidewalks();
    world_.map_json = map_.to_json(cfg_.map_size_m, world_lanes_json_order());
    return std::move(world_);
  }

 private:
  // ---- streets -------------------------------------------------------------------------
  double X(int i) const { return city_.origin_m[0] + i * city_.block_size_m; }
  double Y(int j) const { return city_.origin_m[1] + j * city_.block_size_m; }
  int node_id(int i, int j) const { return j * (city_.blocks_x + 1) + i; }

  Street random_street(bool allow_one_way, bool allow_parking) {
    Street s;
    s.lane_w = city_.lane_width_m;
    s.n_fwd = static_cast<int>(rng_.uniform_int(int64_t{1}, int64_t{city_.max_lanes_per_direction}));
    const bool one_way = allow_one_way && rng_.bernoulli(city_.one_way_fraction);
    s.n_bwd = one_way ? 0 : static_cast<int>(rng_.uniform_int(int64_t{1}, int64_t{city_.max_lanes_per_direction}));
    if (one_way && s.n_fwd == 1 && city_.max_lanes_per_direction > 1) s.n_fwd = 2;
    s.parking = allow_parking && rng_.bernoulli(city_.parking_fraction);
    return s;
  }

  void make_streets() {
    const int nx = city_.blocks_x, ny = city_.blocks_y;
    NSG_CHECK(nx >= 2 && ny >= 2, ConfigError, "synth config", "city.blocks_x",
              "at least 2 blocks in x and y (the ring road needs T-junctions on every side)");
    ring_ = static_cast<int>(streets_.size());
    streets_.push_back(random_street(false, rng_.bernoulli(city_.parking_fraction)));
    for (int i = 1; i < nx; ++i) {
      vertical_[i] = static_cast<int>(streets_.size());
      streets_.push_back(random_street(true, true));
    }
    for (int j = 1; j < ny; ++j) {
      horizontal_[j] = static_cast<int>(streets_.size());
      streets_.push_back(random_street(true, true));
    }
    // Intersections: interior crossings and T-junctions on the ring (no node at the corners).
    nodes_.resize(static_cast<size_t>((nx + 1) * (ny + 1)));
    for (int j = 0; j <= ny; ++j) {
      for (int i = 0; i <= nx; ++i) {
        Intersection& n = nodes_[static_cast<size_t>(node_id(i, j))];
        n.centre = {X(i), Y(j)};
        const bool corner = (i == 0 || i == nx) && (j == 0 || j == ny);
        if (corner) continue;
        const Street& sv = streets_[static_cast<size_t>(i == 0 || i == nx ? ring_ : vertical_.at(i))];
        const Street& sh = streets_[static_cast<size_t>(j == 0 || j == ny ? ring_ : horizontal_.at(j))];
        const StreetLayout lv = layout_of(sv, rht_), lh = layout_of(sh, rht_);
        n.half_m = std::max({lv.left_edge, -lv.right_edge, lh.left_edge, -lh.right_edge}) + 0.5;
        n.arms = (i == 0 || i == nx || j == 0 || j == ny) ? 3 : 4;
      }
    }
  }

  // ---- pieces --------------------------------------------------------------------------
  double ext(int node) const { return nodes_[static_cast<size_t>(node)].half_m + kCrosswalkDepthM; }

  void add_straight_piece(int street, int na, int nb) {
    const Eigen::Vector2d a = nodes_[static_cast<size_t>(na)].centre, b = nodes_[static_cast<size_t>(nb)].centre;
    const Eigen::Vector2d t = (b - a).normalized();
    Piece p;
    p.street = street;
    p.node_a = na;
    p.node_b = nb;
    p.ext_a = ext(na);
    p.ext_b = ext(nb);
    const Eigen::Vector2d s = a + t * p.ext_a;
    p.prims.push_back({{s.x(), s.y(), std::atan2(t.y(), t.x())}, (b - a).norm() - p.ext_a - p.ext_b, 0.0});
    pieces_.push_back(p);
  }

  // Ring corner: straight from node a to the corner's tangent point, quarter arc left,
  // straight to node b.
  void add_corner_piece(int na, int nb, const Eigen::Vector2d& corner) {
    const double rc = city_.ring_corner_radius_m;
    const Eigen::Vector2d a = nodes_[static_cast<size_t>(na)].centre, b = nodes_[static_cast<size_t>(nb)].centre;
    const Eigen::Vector2d t1 = (corner - a).normalized(), t2 = (b - corner).normalized();
    Piece p;
    p.street = ring_;
    p.node_a = na;
    p.node_b = nb;
    p.ext_a = ext(na);
    p.ext_b = ext(nb);
    const Eigen::Vector2d s = a + t1 * p.ext_a;
    const double yaw1 = std::atan2(t1.y(), t1.x());
    p.prims.push_back({{s.x(), s.y(), yaw1}, (corner - a).norm() - rc - p.ext_a, 0.0});
    const Eigen::Vector2d tp1 = corner - t1 * rc;
    p.prims.push_back({{tp1.x(), tp1.y(), yaw1}, kPi / 2.0 * rc, 1.0 / rc});
    const Eigen::Vector2d tp2 = corner + t2 * rc;
    p.prims.push_back({{tp2.x(), tp2.y(), std::atan2(t2.y(), t2.x())}, (b - corner).norm() - rc - p.ext_b, 0.0});
    pieces_.push_back(p);
  }

  void make_pieces() {
    const int nx = city_.blocks_x, ny = city_.blocks_y;
    for (int i = 1; i < nx; ++i)
      for (int j = 0; j < ny; ++j) add_straight_piece(vertical_.at(i), node_id(i, j), node_id(i, j + 1));
    for (int j = 1; j < ny; ++j)
      for (int i = 0; i < nx; ++i) add_straight_piece(horizontal_.at(j), node_id(i, j), node_id(i + 1, j));
    // The ring, counter-clockwise: bottom (+x), right (+y), top (−x), left (−y).
    for (int i = 1; i + 1 < nx; ++i) add_straight_piece(ring_, node_id(i, 0), node_id(i + 1, 0));
    add_corner_piece(node_id(nx - 1, 0), node_id(nx, 1), {X(nx), Y(0)});
    for (int j = 1; j + 1 < ny; ++j) add_straight_piece(ring_, node_id(nx, j), node_id(nx, j + 1));
    add_corner_piece(node_id(nx, ny - 1), node_id(nx - 1, ny), {X(nx), Y(ny)});
    for (int i = nx - 1; i > 1; --i) add_straight_piece(ring_, node_id(i, ny), node_id(i - 1, ny));
    add_corner_piece(node_id(1, ny), node_id(0, ny - 1), {X(0), Y(ny)});
    for (int j = ny - 1; j > 1; --j) add_straight_piece(ring_, node_id(0, j), node_id(0, j - 1));
    add_corner_piece(node_id(0, 1), node_id(1, 0), {X(0), Y(0)});
  }

  // ---- lanes ---------------------------------------------------------------------------
  std::vector<ArclinePath> lane_paths(const Piece& piece, double d, bool forward) {
    std::vector<Prim> prims;
    for (const Prim& p : piece.prims) prims.push_back(offset_prim(p, d));
    if (!forward) {
      std::reverse(prims.begin(), prims.end());
      for (Prim& p : prims) p = reverse_prim(p);
    }
    std::vector<ArclinePath> paths;
    Pose2 start = prims.front().start;
    for (const Prim& p : prims) {
      paths.push_back(p.curvature == 0.0 ? straight_path(start, p.length, rng_)
                                         : arc_path(start, p.length, p.curvature));
      start = paths.back().end_pose;
    }
    return paths;
  }

  void make_lanes() {
    for (size_t pi = 0; pi < pieces_.size(); ++pi) {
      const Piece& piece = pieces_[pi];
      const Street& st = streets_[static_cast<size_t>(piece.street)];
      const StreetLayout lay = layout_of(st, rht_);
      const double L = piece.length();
      // Road segment + road blocks (one per direction).
      const std::vector<Eigen::Vector2d> left = piece_curve(piece, 0.0, L, lay.left_edge, 4.0);
      const std::vector<Eigen::Vector2d> right = piece_curve(piece, 0.0, L, lay.right_edge, 4.0);
      const std::string seg = map_.road_segment(band_ring(left, right), false);
      for (int dir = 0; dir < 2; ++dir) {
        const bool forward = dir == 0;
        const std::vector<double>& offs = forward ? lay.fwd_offsets : lay.bwd_offsets;
        if (offs.empty()) {
          piece_block_[pi][dir] = "";
          continue;
        }
        const double inner = forward ? lay.fwd_inner : lay.bwd_inner;
        const double outer_edge = (forward ? lay.fwd_outer : lay.bwd_outer) > inner ? lay.left_edge : lay.right_edge;
        const double lo = std::min(inner, outer_edge), hi = std::max(inner, outer_edge);
        std::vector<Eigen::Vector2d> l = piece_curve(piece, 0.0, L, hi, 4.0), r = piece_curve(piece, 0.0, L, lo, 4.0);
        if (!forward) {
          std::reverse(l.begin(), l.end());
          std::reverse(r.begin(), r.end());
          std::swap(l, r);
        }
        const std::string block = map_.road_block(band_ring(l, r), {r.front(), l.front()}, {r.back(), l.back()}, seg);
        piece_block_[pi][dir] = block;
        for (size_t k = 0; k < offs.size(); ++k) {
          LaneBuild lb;
          lb.piece = static_cast<int>(pi);
          lb.forward = forward;
          lb.index = static_cast<int>(k);
          lb.group_size = static_cast<int>(offs.size());
          lb.start_node = forward ? piece.node_a : piece.node_b;
          lb.end_node = forward ? piece.node_b : piece.node_a;
          lb.offset_ref = offs[k];
          lb.road_block = block;
          LaneInfo lane;
          lane.paths = lane_paths(piece, offs[k], forward);
          lane.length_m = lane_length(lane.paths);
          lane.offset_from_centre_m = forward ? offs[k] : -offs[k];
          lane.two_way_road = st.two_way();
          add_lane_record(piece, st, lay, lb, lane);
          builds_.push_back(lb);
          world_.lanes.push_back(std::move(lane));
        }
      }
      // Dividers: road divider on the centre line of two-way streets; lane dividers between
      // same-direction lanes.
      if (st.two_way()) map_.road_divider(piece_curve(piece, 0.0, L, 0.0, 4.0), seg);
      for (int dir = 0; dir < 2; ++dir) {
        const std::vector<double>& offs = dir == 0 ? lay.fwd_offsets : lay.bwd_offsets;
        for (size_t k = 1; k < offs.size(); ++k) {
          map_.lane_divider(piece_curve(piece, 0.0, L, (offs[k] + offs[k - 1]) / 2.0, 4.0), "SINGLE_DASHED_WHITE");
        }
      }
    }
  }

  // The lane polygon with its divider segments and edge lines.
  void add_lane_record(const Piece& piece, const Street& st, const StreetLayout& lay, const LaneBuild& lb,
                       LaneInfo& lane) {
    const double w = st.lane_w;
    const double L = piece.length();
    // Boundaries in the lane's own direction: left = +w/2 of its own frame.
    const double sgn = lb.forward ? 1.0 : -1.0;
    const double d_left = lb.offset_ref + sgn * w / 2.0, d_right = lb.offset_ref - sgn * w / 2.0;
    std::vector<Eigen::Vector2d> l = piece_curve(piece, 0.0, L, d_left, 4.0);
    std::vector<Eigen::Vector2d> r = piece_curve(piece, 0.0, L, d_right, 4.0);
    if (!lb.forward) {
      std::reverse(l.begin(), l.end());
      std::reverse(r.begin(), r.end());
    }
    auto boundary_type = [&](double d) -> std::string {
      if (st.two_way() && std::fabs(d) < 1e-6) return rht_ ? "DOUBLE_SOLID_YELLOW" : "DOUBLE_SOLID_WHITE";
      const double edge_span = std::max(std::fabs(lay.fwd_outer), std::fabs(lay.bwd_outer));
      if (std::fabs(std::fabs(d) - edge_span) < 1e-6 || std::fabs(d - lay.fwd_outer) < 1e-6 ||
          std::fabs(d - lay.fwd_inner) < 1e-6 || std::fabs(d - lay.bwd_outer) < 1e-6)
        return st.parking ? "SINGLE_SOLID_WHITE" : "NIL";
      return "SINGLE_DASHED_WHITE";
    };
    lane.token = map_.lane(l, r, boundary_type(d_left), boundary_type(d_right));
  }

  // ---- connectors ----------------------------------------------------------------------
  void make_connectors() {
    const size_t n_lanes = world_.lanes.size();
    std::map<int, std::vector<int>> in_by_node, out_by_node;
    for (size_t i = 0; i < n_lanes; ++i) {
      in_by_node[builds_[i].end_node].push_back(static_cast<int>(i));
      out_by_node[builds_[i].start_node].push_back(static_cast<int>(i));
    }
    for (size_t ni = 0; ni < nodes_.size(); ++ni) {
      Intersection& node = nodes_[ni];
      if (node.arms == 0) continue;
      const double h = node.half_m;
      std::vector<Eigen::Vector2d> square = {node.centre + Eigen::Vector2d(-h, -h),
                                             node.centre + Eigen::Vector2d(h, -h), node.centre + Eigen::Vector2d(h, h),
                                             node.centre + Eigen::Vector2d(-h, h)};
      node.segment_token = map_.road_segment(square, true);
      const std::vector<int>& ins = in_by_node[static_cast<int>(ni)];
      const std::vector<int>& outs = out_by_node[static_cast<int>(ni)];
      for (int a : ins) {
        const Pose2 A = lane_end_pose(world_.lanes[static_cast<size_t>(a)]);
        const LaneBuild& la = builds_[static_cast<size_t>(a)];
        std::vector<int> moves;  // out lanes
        std::vector<int> fallback;
        for (int b : outs) {
          const LaneBuild& lb = builds_[static_cast<size_t>(b)];
          if (lb.piece == la.piece) continue;  // no U-turns
          const Pose2& B = world_.lanes[static_cast<size_t>(b)].paths.front().start_pose;
          const double turn = geometry::wrap_angle_devkit(B.yaw - A.yaw);
          const bool straight = std::fabs(turn) < kPi / 4.0;
          const bool near_turn = !straight && ((turn < 0) == rht_);
          bool take = false;
          if (straight) take = lb.index == std::min(la.index, lb.group_size - 1);
          else if (near_turn) take = la.index == la.group_size - 1 && lb.index == lb.group_size - 1;
          else take = la.index == 0 && lb.index == 0;
          if (take) moves.push_back(b);
          else if (lb.index == (near_turn ? lb.group_size - 1 : 0)) fallback.push_back(b);
        }
        if (moves.empty() && !fallback.empty()) moves.push_back(fallback.front());
        for (int b : moves) add_connector(a, b);
      }
      // An outgoing lane nobody reaches (more lanes out than in) forks off the incoming
      // lane heading the same way that is nearest to it, else off any other arm.
      for (int b : outs) {
        if (!world_.lanes[static_cast<size_t>(b)].incoming.empty()) continue;
        const LaneBuild& lb = builds_[static_cast<size_t>(b)];
        const Pose2& B = world_.lanes[static_cast<size_t>(b)].paths.front().start_pose;
        int best = -1;
        double best_cost = 1e300;
        for (int a : ins) {
          const LaneBuild& la = builds_[static_cast<size_t>(a)];
          if (la.piece == lb.piece) continue;
          const double turn =
              std::fabs(geometry::wrap_angle_devkit(B.yaw - lane_end_pose(world_.lanes[static_cast<size_t>(a)]).yaw));
          const double cost = (turn < kPi / 4.0 ? 0.0 : 100.0) + std::abs(la.index - lb.index);
          if (cost < best_cost) best_cost = cost, best = a;
        }
        if (best >= 0) add_connector(best, b);
      }
      make_crossings(static_cast<int>(ni));
    }
  }

  void add_connector(int a, int b) {
    const Pose2 A = lane_end_pose(world_.lanes[static_cast<size_t>(a)]);
    const Pose2 B = world_.lanes[static_cast<size_t>(b)].paths.front().start_pose;
    const double c = std::cos(A.yaw), s = std::sin(A.yaw);
    const double fx = c * (B.x - A.x) + s * (B.y - A.y), ly = -s * (B.x - A.x) + c * (B.y - A.y);
    const double turn = geometry::wrap_angle_devkit(B.yaw - A.yaw);
    const double radius =
        std::fabs(turn) < kPi / 4.0 ? kStraightRadiusM : std::max(2.0, 0.98 * std::min(std::fabs(fx), std::fabs(ly)));
    ArclinePath path = dubins_path(A, B, radius);
    const Pose2 end = geometry::arcline_pose_at(path, path.length_m());
    if (std::hypot(end.x - B.x, end.y - B.y) > 1e-3)
      throw InternalError("", "lane connector",
                          strprintf("Dubins end misses the lane start by %g m", std::hypot(end.x - B.x, end.y - B.y)));
    LaneInfo conn;
    conn.is_connector = true;
    conn.paths = {path};
    conn.length_m = path.length_m();
    // Placeholder polygon like real connectors: the centreline buffered by half a lane.
    std::vector<Eigen::Vector2d> l, r;
    for (const Pose2& p : geometry::discretize_arcline(path, 2.0)) {
      const Eigen::Vector2d n(-std::sin(p.yaw), std::cos(p.yaw));
      l.push_back(Eigen::Vector2d(p.x, p.y) + n * 1.5);
      r.push_back(Eigen::Vector2d(p.x, p.y) - n * 1.5);
    }
    conn.token = map_.lane_connector(band_ring(l, r));
    const int ci = static_cast<int>(world_.lanes.size());
    world_.lanes.push_back(std::move(conn));
    world_.lanes[static_cast<size_t>(a)].outgoing.push_back(ci);
    world_.lanes[static_cast<size_t>(ci)].incoming.push_back(a);
    world_.lanes[static_cast<size_t>(ci)].outgoing.push_back(b);
    world_.lanes[static_cast<size_t>(b)].incoming.push_back(ci);
  }

  // Ped crossings on every arm, stop lines before them, traffic lights at 4-way crossings.
  void make_crossings(int ni) {
    const Intersection& node = nodes_[static_cast<size_t>(ni)];
    for (size_t pi = 0; pi < pieces_.size(); ++pi) {
      const Piece& piece = pieces_[pi];
      for (int end = 0; end < 2; ++end) {
        if ((end == 0 ? piece.node_a : piece.node_b) != ni) continue;
        const StreetLayout lay = layout_of(streets_[static_cast<size_t>(piece.street)], rht_);
        const double L = piece.length();
        // Crosswalk zone in piece coordinates.
        const double s0 = end == 0 ? -kCrosswalkDepthM + 0.5 : L + 0.5;
        const double s1 = end == 0 ? -0.5 : L + kCrosswalkDepthM - 0.5;
        const Prim& prim = end == 0 ? piece.prims.front() : piece.prims.back();
        const double base = end == 0 ? 0.0 : L - prim.length;
        auto pt = [&](double s, double d) { return prim_point(prim, s - base, d); };
        const std::string pc = map_.ped_crossing(
            {pt(s0, lay.right_edge), pt(s1, lay.right_edge), pt(s1, lay.left_edge), pt(s0, lay.left_edge)},
            node.segment_token);
        // Incoming direction at this end: forward lanes end at node_b, backward at node_a.
        const int dir = end == 1 ? 0 : 1;
        const std::string& block = piece_block_[pi][dir];
        if (block.empty()) continue;
        const double in_lo = dir == 0 ? std::min(lay.fwd_inner, lay.fwd_outer) : std::min(lay.bwd_inner, lay.bwd_outer);
        const double in_hi = dir == 0 ? std::max(lay.fwd_inner, lay.fwd_outer) : std::max(lay.bwd_inner, lay.bwd_outer);
        const double t0 = end == 1 ? L - 0.5 : 0.0, t1 = end == 1 ? L : 0.5;
        std::vector<std::string> lights;
        if (node.arms == 4) {
          const double curb = dir == 0 ? (lay.fwd_outer > lay.fwd_inner ? lay.left_edge : lay.right_edge)
                                       : (lay.bwd_outer > lay.bwd_inner ? lay.left_edge : lay.right_edge);
          const double sl = end == 1 ? L + kCrosswalkDepthM : -kCrosswalkDepthM;
          const Eigen::Vector2d p0 = pt(sl, curb), p1 = pt(sl, curb * 0.5);
          const double yaw = end == 1 ? prim.start.yaw + kPi : prim.start.yaw;  // faces the traffic
          lights.push_back(map_.traffic_light({p0, p1}, block, opposite_blocks(ni, static_cast<int>(pi)), yaw));
          world_.poles.push_back(ScenePole{p0, 0.15, 5.5, SemanticClass::kPoleSign, 70, {60, 60, 60}});
        }
        map_.stop_line({pt(t0, in_lo), pt(t1, in_lo), pt(t1, in_hi), pt(t0, in_hi)},
                       lights.empty() ? "PED_CROSSING" : "TRAFFIC_LIGHT",
                       lights.empty() ? std::vector<std::string>{pc} : std::vector<std::string>{}, lights, block);
      }
    }
  }

  std::vector<std::string> opposite_blocks(int ni, int from_piece) {
    std::vector<std::string> out;
    for (size_t pi = 0; pi < pieces_.size(); ++pi) {
      if (static_cast<int>(pi) == from_piece) continue;
      const Piece& p = pieces_[pi];
      if (p.node_a == ni && !piece_block_[pi][0].empty()) out.push_back(piece_block_[pi][0]);
      if (p.node_b == ni && !piece_block_[pi][1].empty()) out.push_back(piece_block_[pi][1]);
    }
    return out;
  }

  // ---- ground --------------------------------------------------------------------------
  void make_ground() {
    const double res = city_.ground_resolution_m;
    const double margin = city_.sidewalk_width_m + 15.0;
    const double x0 = X(0) - margin, y0 = Y(0) - margin;
    const double x1 = X(city_.blocks_x) + margin, y1 = Y(city_.blocks_y) + margin;
    world_.bounds_m = {x0, y0, x1, y1};
    auto raster = std::make_shared<GroundRaster>(x0, y0, res, static_cast<int>(std::ceil((x1 - x0) / res)),
                                                 static_cast<int>(std::ceil((y1 - y0) / res)));
    GroundRaster& r = *raster;
    // Parks: whole blocks of vegetation (roads and sidewalks drawn over their edges).
    for (int j = 0; j < city_.blocks_y; ++j) {
      for (int i = 0; i < city_.blocks_x; ++i) {
        const bool park = rng_.bernoulli(city_.park_fraction);
        park_blocks_.push_back(park);
        if (!park) continue;
        Prim p{{X(i), (Y(j) + Y(j + 1)) / 2.0, 0.0}, city_.block_size_m, 0.0};
        paint_band(r, p, 0.0, city_.block_size_m, -city_.block_size_m / 2.0, city_.block_size_m / 2.0,
                   GroundMaterial::kVegetation);
      }
    }
    const double sw = city_.sidewalk_width_m;
    for (int pass = 0; pass < 4; ++pass) {
      for (const Piece& piece : pieces_) {
        const Street& st = streets_[static_cast<size_t>(piece.street)];
        const StreetLayout lay = layout_of(st, rht_);
        for (const DrawPrim& dp : draw_prims(piece)) {
          if (pass == 0) {
            paint_band(r, dp.prim, dp.s0, dp.s1, lay.left_edge, lay.left_edge + sw, GroundMaterial::kSidewalk);
            paint_band(r, dp.prim, dp.s0, dp.s1, lay.right_edge - sw, lay.right_edge, GroundMaterial::kSidewalk);
          } else if (pass == 1) {
            paint_band(r, dp.prim, dp.s0, dp.s1, lay.left_edge, lay.left_edge + kCurbWidthM, GroundMaterial::kCurbTop);
            paint_band(r, dp.prim, dp.s0, dp.s1, lay.right_edge - kCurbWidthM, lay.right_edge,
                       GroundMaterial::kCurbTop);
          } else if (pass == 2) {
            paint_band(r, dp.prim, dp.s0, dp.s1, lay.right_edge, lay.left_edge, GroundMaterial::kAsphalt);
          } else {
            paint_markings(r, piece, st, lay, dp);
          }
        }
      }
    }
    world_.ground = raster;
  }

  void paint_markings(GroundRaster& r, const Piece& piece, const Street& st, const StreetLayout& lay,
                      const DrawPrim& dp) {
    const double L = piece.length();
    const double s0 = std::max(0.0, dp.s0), s1 = std::min(dp.prim.length, dp.s1);
    const GroundMaterial centre = rht_ ? GroundMaterial::kPaintYellow : GroundMaterial::kPaintWhite;
    if (st.two_way()) {
      paint_band(r, dp.prim, s0, s1, 0.1, 0.25, centre);
      paint_band(r, dp.prim, s0, s1, -0.25, -0.1, centre);
    }
    const double off = dp.s_offset;
    auto dashed = [off](double s, double) { return std::fmod(s + off, 9.0) < 3.0; };
    for (const auto* offs : {&lay.fwd_offsets, &lay.bwd_offsets}) {
      for (size_t k = 1; k < offs->size(); ++k) {
        const double b = ((*offs)[k] + (*offs)[k - 1]) / 2.0;
        paint_band(r, dp.prim, s0, s1, b - 0.075, b + 0.075, GroundMaterial::kPaintWhite, dashed);
      }
    }
    if (st.parking) {
      for (double e : {lay.fwd_outer, lay.bwd_outer}) {
        if (std::fabs(e) < 1e-9) continue;
        paint_band(r, dp.prim, s0, s1, e - 0.075, e + 0.075, GroundMaterial::kPaintWhite);
      }
    }
    // Stop lines (incoming lanes) and crosswalk stripes at the ends.
    auto span = [](double a, double b) { return std::make_pair(std::min(a, b), std::max(a, b)); };
    if (dp.s_offset + dp.prim.length >= L - 1e-9) {  // last prim: forward lanes arrive at node_b
      if (!lay.fwd_offsets.empty()) {
        const auto [lo, hi] = span(lay.fwd_inner, lay.fwd_outer);
        paint_band(r, dp.prim, dp.prim.length - 0.5, dp.prim.length, lo, hi, GroundMaterial::kPaintWhite);
      }
      paint_band(r, dp.prim, dp.prim.length + 0.5, dp.prim.length + kCrosswalkDepthM - 0.5, lay.right_edge,
                 lay.left_edge, GroundMaterial::kCrosswalkPaint,
                 [&lay](double, double d) { return std::fmod(d - lay.right_edge, 1.0) < 0.5; });
    }
    if (dp.s_offset == 0.0) {
      if (!lay.bwd_offsets.empty()) {
        const auto [lo, hi] = span(lay.bwd_inner, lay.bwd_outer);
        paint_band(r, dp.prim, 0.0, 0.5, lo, hi, GroundMaterial::kPaintWhite);
      }
      paint_band(r, dp.prim, -kCrosswalkDepthM + 0.5, -0.5, lay.right_edge, lay.left_edge,
                 GroundMaterial::kCrosswalkPaint,
                 [&lay](double, double d) { return std::fmod(d - lay.right_edge, 1.0) < 0.5; });
    }
  }

  // ---- other map areas -----------------------------------------------------------------
  void make_map_areas() {
    // Walkways along every piece side; drivable area = all road segment outlines.
    std::vector<std::string> drivable;
    for (size_t pi = 0; pi < pieces_.size(); ++pi) {
      const Piece& piece = pieces_[pi];
      const StreetLayout lay = layout_of(streets_[static_cast<size_t>(piece.street)], rht_);
      const double L = piece.length();
      const double sw = city_.sidewalk_width_m;
      map_.walkway(band_ring(piece_curve(piece, 0.0, L, lay.left_edge + sw, 4.0),
                             piece_curve(piece, 0.0, L, lay.left_edge, 4.0)));
      map_.walkway(band_ring(piece_curve(piece, 0.0, L, lay.right_edge, 4.0),
                             piece_curve(piece, 0.0, L, lay.right_edge - sw, 4.0)));
      drivable.push_back(
          map_.polygon(band_ring(piece_curve(piece, -piece.ext_a, L + piece.ext_b, lay.left_edge, 4.0),
                                 piece_curve(piece, -piece.ext_a, L + piece.ext_b, lay.right_edge, 4.0))));
    }
    map_.drivable_area(drivable);
  }

  // ---- buildings, poles ----------------------------------------------------------------
  bool footprint_free(double cx, double cy, double hx, double hy) const {
    for (double x = cx - hx; x <= cx + hx + 1e-9; x += std::max(0.5, hx / 4.0)) {
      for (double y = cy - hy; y <= cy + hy + 1e-9; y += std::max(0.5, hy / 4.0)) {
        if (world_.ground->material(x, y) != GroundMaterial::kTerrain) return false;
      }
    }
    for (const SceneBox& b : world_.buildings) {
      const bool rot = std::fabs(std::sin(b.yaw_rad)) > 0.5;
      const double bx = (rot ? b.width_m : b.length_m) / 2.0, by = (rot ? b.length_m : b.width_m) / 2.0;
      if (std::fabs(b.center_m.x() - cx) < bx + hx + 1.0 && std::fabs(b.center_m.y() - cy) < by + hy + 1.0)
        return false;
    }
    return true;
  }

  void make_buildings_and_poles() {
    const double B = city_.block_size_m;
    for (int j = 0; j < city_.blocks_y; ++j) {
      for (int i = 0; i < city_.blocks_x; ++i) {
        if (park_blocks_[static_cast<size_t>(j * city_.blocks_x + i)]) {
          const int trees = static_cast<int>(rng_.uniform_int(int64_t{4}, int64_t{12}));
          for (int t = 0; t < trees; ++t) {
            const Eigen::Vector2d p(X(i) + rng_.uniform(0.25, 0.75) * B, Y(j) + rng_.uniform(0.25, 0.75) * B);
            if (world_.ground->material(p.x(), p.y()) != GroundMaterial::kVegetation) continue;
            world_.poles.push_back(
                ScenePole{p, 0.3, rng_.uniform(4.0, 9.0), SemanticClass::kVegetation, 40, {60, 110, 50}});
          }
          continue;
        }
        // Rows of buildings along the four block sides, set back from the sidewalk.
        for (int side = 0; side < 4; ++side) {
          double pos = rng_.uniform(2.0, 10.0);
          while (pos < B) {
            const double front = rng_.uniform(10.0, 28.0), depth = rng_.uniform(10.0, 22.0);
            const double height = rng_.uniform(6.0, 35.0);
            // Distance of the facade from the street axis: first free spot scanning inwards.
            for (double inset = 8.0; inset < B / 2.0 - depth / 2.0; inset += 1.0) {
              double cx, cy, hx, hy;
              const double along = pos + front / 2.0, across = inset + depth / 2.0;
              if (side == 0) cx = X(i) + along, cy = Y(j) + across, hx = front / 2.0, hy = depth / 2.0;
              else if (side == 1) cx = X(i + 1) - across, cy = Y(j) + along, hx = depth / 2.0, hy = front / 2.0;
              else if (side == 2) cx = X(i + 1) - along, cy = Y(j + 1) - across, hx = front / 2.0, hy = depth / 2.0;
              else cx = X(i) + across, cy = Y(j + 1) - along, hx = depth / 2.0, hy = front / 2.0;
              if (!footprint_free(cx, cy, hx, hy)) continue;
              const uint8_t shade = static_cast<uint8_t>(rng_.uniform_int(int64_t{110}, int64_t{200}));
              SceneBox b;
              b.center_m = {cx, cy, height / 2.0};
              b.yaw_rad = 0.0;
              b.length_m = 2.0 * hx;
              b.width_m = 2.0 * hy;
              b.height_m = height;
              b.cls = SemanticClass::kBuilding;
              b.lidar_intensity = static_cast<uint8_t>(rng_.uniform_int(int64_t{20}, int64_t{60}));
              b.rgb = {shade, static_cast<uint8_t>(shade * 0.9), static_cast<uint8_t>(shade * 0.8)};
              world_.buildings.push_back(b);
              break;
            }
            pos += front + rng_.uniform(2.0, 8.0);
          }
        }
      }
    }
    // Street lights along both sidewalks, every ~30 m.
    for (const Piece& piece : pieces_) {
      const StreetLayout lay = layout_of(streets_[static_cast<size_t>(piece.street)], rht_);
      const double L = piece.length();
      for (double s = 8.0; s < L - 8.0; s += 30.0) {
        for (double d : {lay.left_edge + 0.8, lay.right_edge - 0.8}) {
          const Eigen::Vector2d p = piece_point(piece, s, d);
          world_.poles.push_back(ScenePole{p, 0.12, 7.0, SemanticClass::kPoleSign, 80, {120, 120, 125}});
        }
      }
    }
  }

  void make_parking_and_sidewalks() {
    for (size_t pi = 0; pi < pieces_.size(); ++pi) {
      const Piece& piece = pieces_[pi];
      const Street& st = streets_[static_cast<size_t>(piece.street)];
      const StreetLayout lay = layout_of(st, rht_);
      const double sw = city_.sidewalk_width_m;
      for (const Prim& prim : piece.prims) {
        if (prim.curvature == 0.0) {
          for (double d : {lay.left_edge + sw / 2.0, lay.right_edge - sw / 2.0}) {
            const Eigen::Vector2d p = prim_point(prim, 0.0, d);
            world_.sidewalks.push_back({{p.x(), p.y(), prim.start.yaw}, prim.length});
          }
          if (st.parking && prim.length > 12.0) {
            for (int dir = 0; dir < 2; ++dir) {
              const double outer = dir == 0 ? lay.fwd_outer : lay.bwd_outer;
              if (dir == 1 && !st.two_way()) continue;
              const double sign = outer >= 0.0 ? 1.0 : -1.0;
              const double d_lane =
                  st.two_way() ? outer : (sign > 0 ? lay.left_edge - kParkingWidthM : lay.right_edge + kParkingWidthM);
              const double d_mid = d_lane + sign * kParkingWidthM / 2.0;
              const double yaw = dir == 0 ? prim.start.yaw : geometry::wrap_angle_devkit(prim.start.yaw + kPi);
              const double sa = 3.0, sb = prim.length - 3.0;
              const std::string block = piece_block_[pi][dir].empty() ? piece_block_[pi][0] : piece_block_[pi][dir];
              map_.carpark_area({prim_point(prim, sa, d_lane), prim_point(prim, sb, d_lane),
                                 prim_point(prim, sb, d_lane + sign * kParkingWidthM),
                                 prim_point(prim, sa, d_lane + sign * kParkingWidthM)},
                                yaw, block);
              const double spacing = cfg_.traffic.parked_spacing_m;
              for (double s = sa + spacing / 2.0; s < sb - spacing / 2.0; s += spacing) {
                const Eigen::Vector2d c = prim_point(prim, s, d_mid);
                world_.parking_slots.push_back({c.x(), c.y(), yaw});
              }
            }
          }
        }
      }
    }
  }

  // lanes first, then connectors (file order of the map's lane / lane_connector layers).
  std::vector<MapBuilder::LaneTopology> world_lanes_json_order() const {
    std::vector<MapBuilder::LaneTopology> out;
    for (const LaneInfo& lane : world_.lanes) {
      MapBuilder::LaneTopology t;
      t.token = lane.token;
      t.paths = lane.paths;
      for (int o : lane.outgoing) t.outgoing.push_back(world_.lanes[static_cast<size_t>(o)].token);
      for (int i : lane.incoming) t.incoming.push_back(world_.lanes[static_cast<size_t>(i)].token);
      out.push_back(std::move(t));
    }
    return out;
  }

  const SynthConfig& cfg_;
  const CityConfig& city_;
  bool rht_;
  Rng rng_;
  MapBuilder map_;
  World world_;
  std::vector<Street> streets_;
  int ring_ = 0;
  std::map<int, int> vertical_, horizontal_;
  std::vector<Intersection> nodes_;
  std::vector<Piece> pieces_;
  std::map<size_t, std::array<std::string, 2>> piece_block_;
  std::vector<LaneBuild> builds_;
  std::vector<bool> park_blocks_;
};

}  // namespace

World build_world(const SynthConfig& config, uint64_t seed) {
  config.validate();
  WorldBuilder builder(config, seed);
  return builder.build();  // lanes are all made before the connectors, so lanes come first
}

}  // namespace nsg::synth

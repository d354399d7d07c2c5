// The grid layout of the world builder (world_builder.h): a rectangular street grid inside
// a ring road with rounded corners. Streets, intersections (square areas, traffic lights at
// 4-way crossings) and the road pieces between them; the later stages are layout-agnostic.
// The Rng draws here come first in the build, so their order is part of the output.
#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

#include "nsg/core/error.h"
#include "nsg/core/rng.h"
#include "road_geometry.h"
#include "world_builder.h"

namespace nsg::synth::world_detail {

void WorldBuilder::make_layout() {
  if (city_.layout == CityLayout::kOrganic) {
    make_organic_layout();
    return;
  }
  make_streets();
  make_pieces();
}

// ---- streets -------------------------------------------------------------------------

Street WorldBuilder::random_street(bool allow_one_way, bool allow_parking) {
  Street s;
  s.lane_w = city_.lane_width_m;
  s.n_fwd = static_cast<int>(rng_.uniform_int(int64_t{1}, int64_t{city_.max_lanes_per_direction}));
  const bool one_way = allow_one_way && rng_.bernoulli(city_.one_way_fraction);
  s.n_bwd = one_way ? 0 : static_cast<int>(rng_.uniform_int(int64_t{1}, int64_t{city_.max_lanes_per_direction}));
  if (one_way && s.n_fwd == 1 && city_.max_lanes_per_direction > 1) s.n_fwd = 2;
  s.parking = allow_parking && rng_.bernoulli(city_.parking_fraction);
  return s;
}

void WorldBuilder::make_streets() {
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
      n.signalized = n.arms == 4;
      const double h = n.half_m;
      n.area = {n.centre + Eigen::Vector2d(-h, -h), n.centre + Eigen::Vector2d(h, -h), n.centre + Eigen::Vector2d(h, h),
                n.centre + Eigen::Vector2d(-h, h)};
    }
  }
}

// ---- pieces --------------------------------------------------------------------------

void WorldBuilder::add_straight_piece(int street, int na, int nb) {
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
void WorldBuilder::add_corner_piece(int na, int nb, const Eigen::Vector2d& corner) {
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

void WorldBuilder::make_pieces() {
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

}  // namespace nsg::synth::world_detail

// The surface half of the world builder (world_builder.h): the ground material raster
// (parks, sidewalks, curbs, asphalt, paint), buildings, trees and street lights, parking
// slots and areas, and sidewalk paths. It draws over the road pieces world_roads.cpp made
// and shares the builder's Rng with it, so the order of the calls is part of the output.
#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "map_builder.h"
#include "nsg/core/rng.h"
#include "road_geometry.h"
#include "world_builder.h"

namespace nsg::synth::world_detail {

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

// Fills the cells whose centres lie inside the convex polygon `ring` (either orientation).
void paint_polygon(GroundRaster& r, const std::vector<Eigen::Vector2d>& ring, GroundMaterial m) {
  if (ring.size() < 3) return;
  Eigen::Vector2d lo = ring.front(), hi = ring.front();
  for (const Eigen::Vector2d& p : ring) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const int c0 = std::max(0, static_cast<int>(std::floor((lo.x() - r.x0()) / r.resolution())));
  const int c1 = std::min(r.width() - 1, static_cast<int>(std::floor((hi.x() - r.x0()) / r.resolution())));
  const int r0 = std::max(0, static_cast<int>(std::floor((lo.y() - r.y0()) / r.resolution())));
  const int r1 = std::min(r.height() - 1, static_cast<int>(std::floor((hi.y() - r.y0()) / r.resolution())));
  for (int row = r0; row <= r1; ++row) {
    const double y = r.y0() + (row + 0.5) * r.resolution();
    for (int col = c0; col <= c1; ++col) {
      const double x = r.x0() + (col + 0.5) * r.resolution();
      int pos = 0, neg = 0;
      for (size_t i = 0; i < ring.size(); ++i) {
        const Eigen::Vector2d& a = ring[i];
        const Eigen::Vector2d& b = ring[(i + 1) % ring.size()];
        const double cross = (b.x() - a.x()) * (y - a.y()) - (b.y() - a.y()) * (x - a.x());
        pos += cross >= 0.0, neg += cross <= 0.0;
      }
      if (pos == static_cast<int>(ring.size()) || neg == static_cast<int>(ring.size()))
        r.at(col, row) = static_cast<uint8_t>(m);
    }
  }
}

void paint_disc(GroundRaster& r, const Eigen::Vector2d& centre, double radius_m, GroundMaterial m) {
  const double res = r.resolution();
  const int c0 = std::max(0, static_cast<int>(std::floor((centre.x() - radius_m - r.x0()) / res)));
  const int c1 = std::min(r.width() - 1, static_cast<int>(std::floor((centre.x() + radius_m - r.x0()) / res)));
  const int r0 = std::max(0, static_cast<int>(std::floor((centre.y() - radius_m - r.y0()) / res)));
  const int r1 = std::min(r.height() - 1, static_cast<int>(std::floor((centre.y() + radius_m - r.y0()) / res)));
  for (int row = r0; row <= r1; ++row)
    for (int col = c0; col <= c1; ++col)
      if (std::hypot(r.x0() + (col + 0.5) * res - centre.x(), r.y0() + (row + 0.5) * res - centre.y()) <= radius_m)
        r.at(col, row) = static_cast<uint8_t>(m);
}

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

}  // namespace

// ---- ground --------------------------------------------------------------------------

void WorldBuilder::make_ground() {
  const double res = city_.ground_resolution_m;
  const double margin = city_.sidewalk_width_m + 15.0;
  const double x0 = X(0) - margin, y0 = Y(0) - margin;
  const double x1 = X(city_.blocks_x) + margin, y1 = Y(city_.blocks_y) + margin;
  world_.bounds_m = {x0, y0, x1, y1};
  auto raster = std::make_shared<GroundRaster>(x0, y0, res, static_cast<int>(std::ceil((x1 - x0) / res)),
                                               static_cast<int>(std::ceil((y1 - y0) / res)));
  GroundRaster& r = *raster;
  paint_parks(r);
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
          paint_band(r, dp.prim, dp.s0, dp.s1, lay.right_edge - kCurbWidthM, lay.right_edge, GroundMaterial::kCurbTop);
        } else if (pass == 2) {
          paint_band(r, dp.prim, dp.s0, dp.s1, lay.right_edge, lay.left_edge, GroundMaterial::kAsphalt);
        } else {
          paint_markings(r, piece, st, lay, dp);
        }
      }
    }
    if (pass != 2) continue;
    for (const Intersection& node : nodes_)
      if (node.own_area) paint_polygon(r, node.area, GroundMaterial::kAsphalt);
  }
  world_.ground = raster;
}

// Parks under the roads (roads and sidewalks are drawn over their edges): whole grid
// blocks, or the organic layout's discs.
void WorldBuilder::paint_parks(GroundRaster& r) {
  if (city_.layout == CityLayout::kOrganic) {
    for (const auto& [centre, radius] : parks_) paint_disc(r, centre, radius, GroundMaterial::kVegetation);
    return;
  }
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
}

void WorldBuilder::paint_markings(GroundRaster& r, const Piece& piece, const Street& st, const StreetLayout& lay,
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
  if (dp.s_offset + dp.prim.length >= L - 1e-9 && piece.cross_b) {  // last prim: forward lanes arrive at node_b
    if (!lay.fwd_offsets.empty()) {
      const auto [lo, hi] = span(lay.fwd_inner, lay.fwd_outer);
      paint_band(r, dp.prim, dp.prim.length - 0.5, dp.prim.length, lo, hi, GroundMaterial::kPaintWhite);
    }
    paint_band(r, dp.prim, dp.prim.length + 0.5, dp.prim.length + kCrosswalkDepthM - 0.5, lay.right_edge, lay.left_edge,
               GroundMaterial::kCrosswalkPaint,
               [&lay](double, double d) { return std::fmod(d - lay.right_edge, 1.0) < 0.5; });
  }
  if (dp.s_offset == 0.0 && piece.cross_a) {
    if (!lay.bwd_offsets.empty()) {
      const auto [lo, hi] = span(lay.bwd_inner, lay.bwd_outer);
      paint_band(r, dp.prim, 0.0, 0.5, lo, hi, GroundMaterial::kPaintWhite);
    }
    paint_band(r, dp.prim, -kCrosswalkDepthM + 0.5, -0.5, lay.right_edge, lay.left_edge,
               GroundMaterial::kCrosswalkPaint,
               [&lay](double, double d) { return std::fmod(d - lay.right_edge, 1.0) < 0.5; });
  }
}

// A crossing between two blocks (a map change): the stripes of an arm's crosswalk, across
// the whole road between its curbs, over [s0, s1] of `prim`.
void WorldBuilder::paint_mid_block_crossing(GroundRaster& r, const Prim& prim, double s0, double s1,
                                            const StreetLayout& lay) {
  paint_band(r, prim, s0, s1, lay.right_edge, lay.left_edge, GroundMaterial::kCrosswalkPaint,
             [&lay](double, double d) { return std::fmod(d - lay.right_edge, 1.0) < 0.5; });
}

// A divider made solid (a map change): the dashes' line at `offset_ref` of the piece painted
// without gaps over the stretch paint_markings draws it.
void WorldBuilder::paint_solid_divider(GroundRaster& r, const Piece& piece, double offset_ref) {
  for (const DrawPrim& dp : draw_prims(piece)) {
    const double s0 = std::max(0.0, dp.s0), s1 = std::min(dp.prim.length, dp.s1);
    paint_band(r, dp.prim, s0, s1, offset_ref - 0.075, offset_ref + 0.075, GroundMaterial::kPaintWhite);
  }
}

// ---- buildings, poles ----------------------------------------------------------------

bool WorldBuilder::footprint_free(double cx, double cy, double hx, double hy) const {
  for (double x = cx - hx; x <= cx + hx + 1e-9; x += std::max(0.5, hx / 4.0)) {
    for (double y = cy - hy; y <= cy + hy + 1e-9; y += std::max(0.5, hy / 4.0)) {
      if (world_.ground->material(x, y) != GroundMaterial::kTerrain) return false;
    }
  }
  for (const SceneBox& b : world_.buildings) {
    const bool rot = std::fabs(std::sin(b.yaw_rad)) > 0.5;
    const double bx = (rot ? b.width_m : b.length_m) / 2.0, by = (rot ? b.length_m : b.width_m) / 2.0;
    if (std::fabs(b.center_m.x() - cx) < bx + hx + 1.0 && std::fabs(b.center_m.y() - cy) < by + hy + 1.0) return false;
  }
  return true;
}

void WorldBuilder::make_buildings_and_poles() {
  if (city_.layout == CityLayout::kOrganic) make_free_buildings();
  else make_block_buildings();
  // Street lights along both sidewalks, every ~30 m (where a sidewalk is: not where a ramp
  // runs beside its road).
  for (const Piece& piece : pieces_) {
    const StreetLayout lay = layout_of(streets_[static_cast<size_t>(piece.street)], rht_);
    const double L = piece.length();
    for (double s = 8.0; s < L - 8.0; s += 30.0) {
      for (double d : {lay.left_edge + 0.8, lay.right_edge - 0.8}) {
        const Eigen::Vector2d p = piece_point(piece, s, d);
        if (is_drivable_material(world_.ground->material(p.x(), p.y()))) continue;
        world_.poles.push_back(ScenePole{p, 0.12, 7.0, SemanticClass::kPoleSign, 80, {120, 120, 125}});
      }
    }
  }
}

void WorldBuilder::add_building(double cx, double cy, double hx, double hy, double height) {
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
}

// Grid: trees in park blocks, rows of buildings along the four sides of the others.
void WorldBuilder::make_block_buildings() {
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
            add_building(cx, cy, hx, hy, height);
            break;
          }
          pos += front + rng_.uniform(2.0, 8.0);
        }
      }
    }
  }
}

// Organic: trees in the parks, then buildings wherever a jittered lattice over the city's
// rectangle finds bare terrain (the ground raster keeps them off roads, sidewalks, parks).
void WorldBuilder::make_free_buildings() {
  for (const auto& [centre, radius] : parks_) {
    const int trees = static_cast<int>(rng_.uniform_int(int64_t{4}, int64_t{12}));
    for (int t = 0; t < trees; ++t) {
      const double ang = rng_.uniform(0.0, 2.0 * kPi), rad = radius * std::sqrt(rng_.uniform(0.0, 0.8));
      const Eigen::Vector2d p = centre + rad * Eigen::Vector2d(std::cos(ang), std::sin(ang));
      if (world_.ground->material(p.x(), p.y()) != GroundMaterial::kVegetation) continue;
      world_.poles.push_back(ScenePole{p, 0.3, rng_.uniform(4.0, 9.0), SemanticClass::kVegetation, 40, {60, 110, 50}});
    }
  }
  constexpr double kStepM = 26.0, kSetbackM = 2.0;
  for (double y = Y(0); y < Y(city_.blocks_y); y += kStepM) {
    for (double x = X(0); x < X(city_.blocks_x); x += kStepM) {
      const double hx = rng_.uniform(5.0, 12.0), hy = rng_.uniform(5.0, 11.0), height = rng_.uniform(6.0, 35.0);
      const double cx = x + rng_.uniform(-4.0, 4.0), cy = y + rng_.uniform(-4.0, 4.0);
      if (!footprint_free(cx, cy, hx + kSetbackM, hy + kSetbackM)) continue;
      add_building(cx, cy, hx, hy, height);
    }
  }
}

void WorldBuilder::make_parking_and_sidewalks() {
  for (size_t pi = 0; pi < pieces_.size(); ++pi) {
    const Piece& piece = pieces_[pi];
    const Street& st = streets_[static_cast<size_t>(piece.street)];
    const StreetLayout lay = layout_of(st, rht_);
    const double sw = city_.sidewalk_width_m;
    for (const Prim& prim : piece.prims) {
      if (prim.curvature == 0.0) {
        for (double d : {lay.left_edge + sw / 2.0, lay.right_edge - sw / 2.0}) {
          const Eigen::Vector2d p = prim_point(prim, 0.0, d), mid = prim_point(prim, prim.length / 2.0, d);
          if (is_drivable_material(world_.ground->material(mid.x(), mid.y()))) continue;  // a ramp beside it
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

}  // namespace nsg::synth::world_detail

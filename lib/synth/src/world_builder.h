#pragma once
// The world builder's shared state, internal to the synth module: the street layout types
// and the WorldBuilder class whose members are split by what they make —
// world_layout_grid.cpp / world_layout_organic.cpp: the layout (streets, nodes, pieces);
// world_roads.cpp: lanes, crossings and the map's areas; world_connectors.cpp: connectors;
// world_surface.cpp: the ground raster and its markings, buildings, poles, parking, sidewalks;
// world.cpp: the construction, the build order and the public functions of world.h.
#include <Eigen/Core>
#include <array>
#include <map>
#include <string>
#include <vector>

#include "map_builder.h"
#include "nsg/core/rng.h"
#include "nsg/synth/changes.h"
#include "nsg/synth/world.h"
#include "road_geometry.h"

namespace nsg::synth::world_detail {

using geometry::ArclinePath;
using geometry::ArclineShape;
using geometry::Pose2;

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
  // The innermost forward lane (index 0) is a turn pocket: it only turns across the
  // oncoming traffic (left in right-hand traffic) at the piece's end node.
  bool pocket = false;
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

StreetLayout layout_of(const Street& s, bool rht);

struct Piece {
  int street = 0;
  int node_a = -1;  // intersection at the start / end
  int node_b = -1;
  std::vector<Prim> prims;
  double ext_a = 0.0;  // distance from node centre to the piece start (= box half + crosswalk)
  double ext_b = 0.0;
  bool cross_a = true;  // a crosswalk and stop line at the start / end (not on roundabout rings)
  bool cross_b = true;
  double length() const {
    double l = 0.0;
    for (const Prim& p : prims) l += p.length;
    return l;
  }
};

enum class NodeKind {
  kJunction,    // an intersection area (road_segment with is_intersection) joins its arms
  kTransition,  // no area: the lanes of collinear pieces meet (lane drops, pockets, ramps)
};

struct Intersection {
  Eigen::Vector2d centre;
  double half_m = 0.0;  // grid: half-size of the square box; organic: radius of the junction area
  int arms = 0;
  NodeKind kind = NodeKind::kJunction;
  bool signalized = false;  // traffic lights on every arm (the grid's 4-way crossings)
  // The organic junction area is painted and joins the drivable area; the grid's arms
  // already cover their square.
  bool own_area = false;
  std::vector<Eigen::Vector2d> area;  // the intersection road_segment's polygon
  std::string segment_token;
};

// A lane as built, before connectors.
struct LaneBuild {
  int piece = 0;
  bool forward = true;
  int index = 0;  // 0 = innermost
  int group_size = 1;
  bool pocket = false;        // this lane is a turn pocket (Street::pocket, index 0 forward)
  bool group_pocket = false;  // its direction's group has one
  int start_node = -1, end_node = -1;
  double offset_ref = 0.0;  // in the reference frame
  std::string road_block;
};

// Maps a reference-frame position (s along the piece, d left) to a point, across prims.
Eigen::Vector2d piece_point(const Piece& piece, double s, double d);

// Points along the piece at lateral offset d from s0 to s1, evenly spaced ≤ step apart.
std::vector<Eigen::Vector2d> piece_curve(const Piece& piece, double s0, double s1, double d, double step);

// The prims of a piece with s ranges, the first/last (straight) extended to node centres.
struct DrawPrim {
  Prim prim;
  double s0, s1;
  double s_offset;  // piece-level s at prim s = 0
};

// A lane divider between two lanes of one direction, as built (a map change may retype it).
struct DividerBuild {
  std::string token;
  int piece = 0;
  bool forward = true;
  int group_size = 2;
  double offset_ref = 0.0;  // in the piece's reference frame
};

// Builds the World of build_world(): call build() once. Members in the order build() calls them.
class WorldBuilder {
 public:
  WorldBuilder(const SynthConfig& config, uint64_t seed);

  World build();
  // build()'s world and the same world after config.changes (world_changes.cpp).
  ChangedWorld build_changed();

 private:
  // ---- layout: streets, nodes, pieces (world_layout_grid.cpp, world_layout_organic.cpp) --
  void make_layout();
  double X(int i) const { return city_.origin_m[0] + i * city_.block_size_m; }
  double Y(int j) const { return city_.origin_m[1] + j * city_.block_size_m; }
  int node_id(int i, int j) const { return j * (city_.blocks_x + 1) + i; }
  Street random_street(bool allow_one_way, bool allow_parking);
  void make_streets();
  double ext(int node) const { return nodes_[static_cast<size_t>(node)].half_m + kCrosswalkDepthM; }
  void add_straight_piece(int street, int na, int nb);
  void add_corner_piece(int na, int nb, const Eigen::Vector2d& corner);
  void make_pieces();
  void make_organic_layout();

  // ---- lanes (world_roads.cpp) -----------------------------------------------------------
  std::vector<ArclinePath> lane_paths(const Piece& piece, double d, bool forward);
  void make_lanes();
  void add_lane_record(const Piece& piece, const Street& st, const StreetLayout& lay, const LaneBuild& lb,
                       LaneInfo& lane);

  // ---- connectors (world_connectors.cpp) and crossings (world_roads.cpp) ------------------
  void make_connectors();
  void connect_junction(const std::vector<int>& ins, const std::vector<int>& outs);
  void connect_transition(const std::vector<int>& ins, const std::vector<int>& outs);
  void add_connector(int a, int b);
  void make_crossings(int ni);
  std::vector<std::string> opposite_blocks(int ni, int from_piece);

  // ---- ground (world_surface.cpp) --------------------------------------------------------
  void make_ground();
  void paint_parks(GroundRaster& r);
  void paint_markings(GroundRaster& r, const Piece& piece, const Street& st, const StreetLayout& lay,
                      const DrawPrim& dp);

  // ---- other map areas (world_roads.cpp) -------------------------------------------------
  void make_map_areas();

  // ---- buildings, poles, parking, sidewalks (world_surface.cpp) --------------------------
  bool footprint_free(double cx, double cy, double hx, double hy) const;
  void make_buildings_and_poles();
  void make_block_buildings();
  void make_free_buildings();
  void add_building(double cx, double cy, double hx, double hy, double height);
  void make_parking_and_sidewalks();

  // ---- map changes (world_changes.cpp): each picks its places with `rng` away from `taken`
  // (edit points), records them in `edits` and returns the lanes to remove (indices) --------
  std::vector<int> close_lanes(Rng& rng, std::vector<MapEdit>& edits, std::vector<bool>& removed);
  void remove_turns(Rng& rng, std::vector<MapEdit>& edits, std::vector<bool>& removed);
  void add_turns(Rng& rng, std::vector<MapEdit>& edits, std::vector<bool>& removed);
  void retype_dividers(Rng& rng, std::vector<MapEdit>& edits, const std::vector<bool>& removed, GroundRaster& ground);
  void paint_solid_divider(GroundRaster& r, const Piece& piece, double offset_ref);
  void add_crossings(Rng& rng, std::vector<MapEdit>& edits, GroundRaster& ground);
  void paint_mid_block_crossing(GroundRaster& r, const Prim& prim, double s0, double s1, const StreetLayout& lay);
  bool far_from_edits(const std::vector<MapEdit>& edits, const Eigen::Vector2d& p) const;

  // ---- map JSON (world.cpp) --------------------------------------------------------------
  std::vector<MapBuilder::LaneTopology> world_lanes_json_order() const;

  const SynthConfig& cfg_;
  uint64_t seed_;
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
  std::vector<std::string> piece_segment_;  // each piece's road_segment token
  std::vector<LaneBuild> builds_;
  std::vector<DividerBuild> dividers_;
  std::vector<bool> park_blocks_;
  std::vector<std::pair<Eigen::Vector2d, double>> parks_;  // organic: centre and radius of each park
};

}  // namespace nsg::synth::world_detail

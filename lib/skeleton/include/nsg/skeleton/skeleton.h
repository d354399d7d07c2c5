#pragma once
// From a centreline likelihood map (or a mask) to an undirected anchor graph: smooth,
// threshold, drop small blobs, thin, trace the skeleton into branches, prune spurs, place
// anchors at most `anchor_spacing_px` apart along the simplified branches. The reference
// model's b1 (nsg::model::extract_graph) orients and scores this graph; `nsgraph graphify`
// writes it as it is.
#include <array>
#include <string>
#include <type_traits>
#include <vector>

#include <opencv2/core.hpp>

#include "nsg/core/options.h"

namespace nsg::skeleton {

// The skeleton's parameters. The model's ExtractionOptions derives from this struct, so
// its `extraction.*` keys and graphify's bare keys are one declaration
// (declare_skeleton_options).
struct SkeletonOptions {
  double smooth_sigma_px = 1.0;        // Gaussian on the likelihood before thresholding (0 = none)
  double threshold = 0.5;              // likelihood that makes a pixel part of the skeleton
  int min_component_px = 20;           // smaller blobs are noise, dropped before thinning
  double min_spur_px = 6.0;            // dangling skeleton branches shorter than this are pruned
  double simplify_tolerance_px = 1.0;  // Douglas–Peucker before anchors are placed
  double anchor_spacing_px = 10.0;     // 2 m at 0.2 m/px
  // The crossing rule (split_crossings): lanes that cross share no node in a lane graph,
  // but thinning joins them into one junction. Off here, so the reference model's
  // extraction stays as trained and recorded; graphify turns it on (GraphifyOptions).
  // Declared by declare_crossing_options, not declare_skeleton_options.
  bool split_crossings = false;
  double crossing_tolerance_deg = 30.0;  // how far from 180 deg a straight-through pair may bend
  double crossing_merge_px = 40.0;       // 3-way junctions closer than this may be one crossing
  void validate() const;                 // ConfigError naming the key (skeleton_option_table)
};

// The declarations of SkeletonOptions' keys, `prefix` before each ("extraction." for the
// model, "" for graphify), into the table of SkeletonOptions or of a struct derived from it
// (a base's member pointer converts to the derived struct's).
template <typename Owner>
void declare_skeleton_options(options::Table<Owner>& t, const std::string& prefix) {
  static_assert(std::is_base_of_v<SkeletonOptions, Owner>);
  const options::Range open_unit{0.0, 1.0, true, true, {}};  // (0, 1)
  t.number(prefix + "smooth_sigma_px", static_cast<double Owner::*>(&SkeletonOptions::smooth_sigma_px))
      .unit("px")
      .range(options::between(0, 10))
      .help("Gaussian on the likelihood before thresholding (0 = none)");
  t.number(prefix + "threshold", static_cast<double Owner::*>(&SkeletonOptions::threshold))
      .range(open_unit)
      .help("Likelihood that makes a pixel part of the skeleton");
  t.integer(prefix + "min_component_px", static_cast<int Owner::*>(&SkeletonOptions::min_component_px))
      .unit("px")
      .range(options::at_least(0))
      .help("Smaller blobs are dropped before thinning");
  t.number(prefix + "min_spur_px", static_cast<double Owner::*>(&SkeletonOptions::min_spur_px))
      .unit("px")
      .range(options::at_least(0))
      .help("Dangling skeleton branches shorter than this are pruned");
  t.number(prefix + "simplify_tolerance_px", static_cast<double Owner::*>(&SkeletonOptions::simplify_tolerance_px))
      .unit("px")
      .range(options::at_least(0))
      .help("Douglas-Peucker tolerance before anchors are placed");
  t.number(prefix + "anchor_spacing_px", static_cast<double Owner::*>(&SkeletonOptions::anchor_spacing_px))
      .unit("px")
      .range(options::at_least(1))
      .help("Spacing of the anchors placed along skeleton branches");
}

// The crossing rule's keys (split_crossings, crossing_*), bare: graphify's alone. The
// model's extraction.* table leaves them out, so its extraction cannot change with them
// (and its model file, which lists the extraction fields it records, stays as it is).
void declare_crossing_options(options::Table<SkeletonOptions>& t);

// SkeletonOptions' own table: the bare keys (threshold, smooth_sigma_px, …, then the
// crossing rule's).
const options::Table<SkeletonOptions>& skeleton_option_table();

// The skeleton as branches between vertices (ends and junctions). Every branch's polyline
// starts at its first vertex's position and ends at its second's (pixel coordinates u, v).
struct SkeletonGraph {
  struct Branch {
    int a = -1, b = -1;
    std::vector<cv::Point2d> points;
  };
  std::vector<cv::Point2d> vertices;
  std::vector<Branch> branches;
};

// Bilinear sample of a CV_32F map at pixel coordinates (u, v); 0 outside the map.
double sample_bilinear(const cv::Mat& map, double u, double v);

// An edge's score: the likelihood sampled about every pixel along the segment a → b
// (both ends included), averaged. The reference model's and graphify's edge scores.
double segment_score(const cv::Mat& likelihood, const std::array<double, 2>& a_uv, const std::array<double, 2>& b_uv);

// The paper's orientation rule: an undirected anchor pair (a, b) gets the orientation —
// a→b or b→a — whose vector has the larger dot product with the sum of the mean
// directions (pixel-frame vectors) at both anchors. Returns true for a→b; ties (including
// no direction evidence) keep a→b. The reference model feeds it LaneDirNet's votes,
// graphify's directed mode a heading map.
bool orient_a_to_b(const std::array<double, 2>& a_uv, const std::array<double, 2>& b_uv,
                   const std::array<double, 2>& mean_dir_a, const std::array<double, 2>& mean_dir_b);

// Drops 8-connected components of a binary mask smaller than min_px (CV_8U 0 / 255 out).
cv::Mat drop_small_components(const cv::Mat& mask, int min_px);
// Zhang–Suen thinning of a binary mask (non-zero = foreground) to a one-pixel skeleton.
cv::Mat thin(const cv::Mat& mask);
// Traces a one-pixel skeleton (non-zero pixels, 8-connected). Staircase diagonals are
// treated as one path; touching junction pixels form one vertex at their mean position;
// closed loops get a vertex where they were first met.
SkeletonGraph trace_skeleton(const cv::Mat& skeleton);
// Removes dangling branches shorter than min_length_px (one pass) and unused vertices.
void prune_spurs(SkeletonGraph& graph, double min_length_px);
// Drops the vertices no branch uses; the others are renumbered in order of first use.
void drop_unused_vertices(SkeletonGraph& graph);

// The crossing rule's parameters (SkeletonOptions' crossing_* keys).
struct CrossingRule {
  double tolerance_deg = 30.0;  // a pair's branches leave at least 180 - this apart
  double merge_px = 40.0;       // 3-way junctions joined by a shorter branch may be one crossing
};
// Lanes that cross share no node in a lane graph; a thinned mask joins them. A junction of
// an even number of branches (4 to 8) that all pair into straight lines (each pair leaving
// in directions within rule.tolerance_deg of opposite), or two 3-way junctions joined by a
// branch shorter than rule.merge_px (thinning's X at a shallow angle) whose branches pair
// across it into straight lines through its middle, is taken apart: each pair becomes one
// branch, its polyline joined through the junction(s), so the lines cross with no shared
// vertex (the shared branch of a pair is dropped). Other junctions (T, Y, splits and
// merges) stay; unused vertices are dropped; a graph without crossings is left as it is.
void split_crossings(SkeletonGraph& graph, const CrossingRule& rule);

// Undirected anchor graph: anchors ≤ spacing apart along every simplified branch; branch
// vertices are shared anchors.
struct AnchorGraph {
  std::vector<std::array<double, 2>> nodes;  // (u, v)
  std::vector<std::array<int, 2>> pairs;     // undirected, as placed along branches
};
AnchorGraph place_anchors(const SkeletonGraph& skeleton, double spacing_px, double simplify_tolerance_px);

// The whole chain on a CV_32F likelihood: smooth, threshold, drop small components, thin,
// trace, prune spurs, place anchors. Options are taken as valid (callers validate).
AnchorGraph skeleton_anchors(const cv::Mat& likelihood, const SkeletonOptions& options);

}  // namespace nsg::skeleton

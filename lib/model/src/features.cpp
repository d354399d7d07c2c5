// Per-pixel features (see features.h). Every map is a 256 × 256 CV_32F image; the final
// matrix has one row per pixel (row-major) and one column per named feature.
#include "nsg/model/features.h"

#include <cmath>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "nsg/core/error.h"
#include "nsg/core/strings.h"

namespace nsg::model {
namespace {

constexpr float kEps = 1e-6f;

// Semantic class groups (samples/semantic-classes.json ids).
struct ClassGroup {
  const char* name;
  std::vector<int> ids;
};
const std::vector<ClassGroup>& class_groups() {
  static const std::vector<ClassGroup> groups = {
      {"road", {0}}, {"marking", {1}},  {"crosswalk", {2}}, {"sidewalk", {3}},
      {"curb", {4}}, {"green", {5, 6}}, {"building", {7}},  {"vehicle", {8, 9}},
  };
  return groups;
}

// Collects named maps; the order of add() calls is the column order.
struct FeatureSink {
  void add(const std::string& name, const cv::Mat& map) {
    names.push_back(name);
    maps.push_back(map);
  }
  std::vector<std::string> names;
  std::vector<cv::Mat> maps;
};

cv::Mat as_float(const cv::Mat& m, double scale = 1.0) {
  cv::Mat f;
  m.convertTo(f, CV_32F, scale);
  return f;
}

// Mask (CV_8U 0/1) → CV_32F 0/1.
cv::Mat mask_float(const cv::Mat& mask) { return as_float(mask != 0, 1.0 / 255.0); }

// Fraction of `mask` pixels in a k × k window (zero padding: windows at the border see
// no data outside the tile, which is what the tile has).
cv::Mat density(const cv::Mat& mask_f, int k) {
  cv::Mat out;
  cv::boxFilter(mask_f, out, CV_32F, {k, k}, {-1, -1}, true, cv::BORDER_CONSTANT);
  return out;
}

// Mean of `values` over the pixels where `valid_f` is 1, in a k × k window; 0 where the
// window holds no valid pixel.
cv::Mat valid_mean(const cv::Mat& values, const cv::Mat& valid_f, int k) {
  cv::Mat num, den;
  cv::boxFilter(values.mul(valid_f), num, CV_32F, {k, k}, {-1, -1}, false, cv::BORDER_CONSTANT);
  cv::boxFilter(valid_f, den, CV_32F, {k, k}, {-1, -1}, false, cv::BORDER_CONSTANT);
  cv::Mat out = num / cv::max(den, kEps);
  out.setTo(0.0f, den < 0.5f);
  return out;
}

// Distance in px from every pixel to the nearest pixel of `mask`, clipped at clip_px and
// divided by it (1 = nothing within clip_px, also when the mask is empty).
cv::Mat clipped_distance(const cv::Mat& mask, float clip_px) {
  if (cv::countNonZero(mask) == 0) return cv::Mat(mask.size(), CV_32F, cv::Scalar(1.0f));
  cv::Mat background = (mask == 0), dist;
  cv::distanceTransform(background, dist, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  return cv::min(dist, clip_px) / clip_px;
}

// Vector (du, dv) from every pixel to the nearest pixel of `mask` (DIST_MASK_5 labels),
// and whether the mask had any pixel at all.
bool nearest_offsets(const cv::Mat& mask, cv::Mat& du, cv::Mat& dv) {
  du = cv::Mat::zeros(mask.size(), CV_32F);
  dv = cv::Mat::zeros(mask.size(), CV_32F);
  if (cv::countNonZero(mask) == 0) return false;
  cv::Mat background = (mask == 0), dist, labels;
  cv::distanceTransform(background, dist, labels, cv::DIST_L2, cv::DIST_MASK_5, cv::DIST_LABEL_PIXEL);
  // Each mask pixel carries its own label: label → position.
  std::vector<cv::Point> where(static_cast<size_t>(mask.total()) + 1, cv::Point(-1, -1));
  for (int v = 0; v < mask.rows; ++v) {
    for (int u = 0; u < mask.cols; ++u) {
      if (mask.at<uint8_t>(v, u)) where[static_cast<size_t>(labels.at<int>(v, u))] = {u, v};
    }
  }
  for (int v = 0; v < mask.rows; ++v) {
    for (int u = 0; u < mask.cols; ++u) {
      const cv::Point p = where[static_cast<size_t>(labels.at<int>(v, u))];
      if (p.x < 0) continue;
      du.at<float>(v, u) = static_cast<float>(p.x - u);
      dv.at<float>(v, u) = static_cast<float>(p.y - v);
    }
  }
  return true;
}

// Orientation of linear structures from the structure tensor of `image`: the line axis
// as a map angle θ (x east, y north) doubled into (cos 2θ, sin 2θ), and the coherence in
// [0, 1] (1 = one clear orientation).
struct Orientation {
  cv::Mat cos2, sin2, coherence;
};

Orientation structure_orientation(const cv::Mat& image, double grad_sigma_px, double window_sigma_px) {
  cv::Mat smooth, gu, gv;
  cv::GaussianBlur(image, smooth, {0, 0}, grad_sigma_px);
  cv::Sobel(smooth, gu, CV_32F, 1, 0, 3);
  cv::Sobel(smooth, gv, CV_32F, 0, 1, 3);
  // In the map frame the v axis points south: g_y = −g_v.
  cv::Mat jxx = gu.mul(gu), jyy = gv.mul(gv), jxy = -gu.mul(gv);
  for (cv::Mat* j : {&jxx, &jyy, &jxy}) cv::GaussianBlur(*j, *j, {0, 0}, window_sigma_px);
  Orientation o;
  o.cos2.create(image.size(), CV_32F);
  o.sin2.create(image.size(), CV_32F);
  o.coherence.create(image.size(), CV_32F);
  for (int v = 0; v < image.rows; ++v) {
    for (int u = 0; u < image.cols; ++u) {
      const float a = jxx.at<float>(v, u), b = jyy.at<float>(v, u), c = jxy.at<float>(v, u);
      const float diff = a - b, trace = a + b;
      const float mag = std::sqrt(diff * diff + 4.0f * c * c);
      // The gradient's doubled angle is (diff, 2c)/mag; the line axis is perpendicular,
      // so its doubled angle is the opposite vector.
      const bool defined = mag > kEps && trace > kEps;
      o.cos2.at<float>(v, u) = defined ? -diff / mag : 0.0f;
      o.sin2.at<float>(v, u) = defined ? -2.0f * c / mag : 0.0f;
      o.coherence.at<float>(v, u) = defined ? mag / trace : 0.0f;
    }
  }
  return o;
}

// The line axis (unit, map frame) of every pixel from the doubled angle.
void axis_from_doubled(const Orientation& o, cv::Mat& ax, cv::Mat& ay) {
  ax.create(o.cos2.size(), CV_32F);
  ay.create(o.cos2.size(), CV_32F);
  for (int v = 0; v < o.cos2.rows; ++v) {
    for (int u = 0; u < o.cos2.cols; ++u) {
      const double theta = 0.5 * std::atan2(o.sin2.at<float>(v, u), o.cos2.at<float>(v, u));
      ax.at<float>(v, u) = static_cast<float>(std::cos(theta));
      ay.at<float>(v, u) = static_cast<float>(std::sin(theta));
    }
  }
}

// `map` sampled at each pixel displaced by t px along the axis normal (+ = left of the
// axis in the map frame), bilinear, 0 outside the tile.
cv::Mat sample_across(const cv::Mat& map, const cv::Mat& ax, const cv::Mat& ay, float t_px) {
  cv::Mat mu(map.size(), CV_32F), mv(map.size(), CV_32F);
  for (int v = 0; v < map.rows; ++v) {
    for (int u = 0; u < map.cols; ++u) {
      // Left normal in the map frame (−a_y, a_x) → pixel frame (du, dv) = (−a_y, −a_x).
      mu.at<float>(v, u) = static_cast<float>(u) - t_px * ay.at<float>(v, u);
      mv.at<float>(v, u) = static_cast<float>(v) - t_px * ax.at<float>(v, u);
    }
  }
  cv::Mat out;
  cv::remap(map, out, mu, mv, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));
  return out;
}

// The travel direction implied by a reference marking on a known side: of the two senses
// of the local axis, the one that has the marking on its left (left = true) or right.
// Returned as map-frame (cos, sin) weighted by exp(−distance / scale_px); 0 without one.
void implied_direction(const cv::Mat& marking, const cv::Mat& ax, const cv::Mat& ay, bool left, float scale_px,
                       cv::Mat& out_x, cv::Mat& out_y) {
  cv::Mat du, dv;
  out_x = cv::Mat::zeros(marking.size(), CV_32F);
  out_y = cv::Mat::zeros(marking.size(), CV_32F);
  if (!nearest_offsets(marking, du, dv)) return;
  for (int v = 0; v < marking.rows; ++v) {
    for (int u = 0; u < marking.cols; ++u) {
      const float ox = du.at<float>(v, u), oy = -dv.at<float>(v, u);  // map frame
      const float a_x = ax.at<float>(v, u), a_y = ay.at<float>(v, u);
      const float side = ox * -a_y + oy * a_x;  // > 0: marking on the left of +axis
      const float sense = ((side > 0) == left) ? 1.0f : -1.0f;
      const float w = std::exp(-std::sqrt(ox * ox + oy * oy) / scale_px);
      out_x.at<float>(v, u) = sense * a_x * w;
      out_y.at<float>(v, u) = sense * a_y * w;
    }
  }
}

// Everything the modality blocks share: masks of markings per source and the orientation.
struct Shared {
  cv::Mat lidar_valid_f, rgb_valid_f, sem_valid_f;
  cv::Mat paint;                   // LiDAR: brighter than its surroundings (CV_8U 0/255)
  cv::Mat yellow, white;           // RGB
  cv::Mat sem_marking, road_edge;  // semantics
  cv::Mat ax, ay;                  // local line axis (map frame)
  Orientation orientation;
};

void lidar_features(const TileInput& t, Shared& s, FeatureSink& out) {
  const cv::Mat intensity = as_float(t.lidar, 1.0 / 255.0);
  const cv::Mat& valid = s.lidar_valid_f;
  out.add("lidar.intensity", intensity);
  out.add("lidar.covered", valid);
  for (int k : {9, 25, 61}) out.add("lidar.coverage_" + std::to_string(k), density(valid, k));
  cv::Mat mean31;
  for (int k : {5, 13, 31}) {
    cv::Mat m = valid_mean(intensity, valid, k);
    if (k == 31) mean31 = m;
    out.add("lidar.mean_" + std::to_string(k), m);
  }
  out.add("lidar.contrast", cv::Mat((intensity - mean31).mul(valid)));
  const cv::Mat paint_f = mask_float(s.paint);
  cv::Mat paint5;
  for (int k : {5, 13, 31}) {
    cv::Mat d = density(paint_f, k);
    if (k == 5) paint5 = d;
    out.add("lidar.paint_" + std::to_string(k), d);
  }
  out.add("lidar.paint_distance", clipped_distance(s.paint, 40.0f));
  // Paint across the lane axis: a centreline has markings ≈ half a lane (8.75 px) away
  // on both sides; symmetric and asymmetric parts at a few distances.
  for (double t : {4.4, 8.75, 13.1, 17.5}) {
    const auto t_px = static_cast<float>(t);
    const std::string d = format_double(t);
    const cv::Mat plus = sample_across(paint5, s.ax, s.ay, t_px), minus = sample_across(paint5, s.ax, s.ay, -t_px);
    out.add("lidar.paint_across_sum_" + d, cv::Mat(plus + minus));
    out.add("lidar.paint_across_diff_" + d, cv::Mat(cv::abs(plus - minus)));
  }
}

void orientation_features(Shared& s, FeatureSink& out) {
  out.add("orientation.cos2", cv::Mat(s.orientation.cos2.mul(s.orientation.coherence)));
  out.add("orientation.sin2", cv::Mat(s.orientation.sin2.mul(s.orientation.coherence)));
  out.add("orientation.coherence", s.orientation.coherence);
}

void rgb_features(const TileInput& t, Shared& s, FeatureSink& out) {
  std::vector<cv::Mat> ch;
  cv::split(as_float(t.rgb, 1.0 / 255.0), ch);
  const char* names[] = {"r", "g", "b"};
  for (int c = 0; c < 3; ++c) out.add(std::string("rgb.") + names[c], ch[c]);
  for (int c = 0; c < 3; ++c) {
    out.add(std::string("rgb.mean_13_") + names[c], valid_mean(ch[c], s.rgb_valid_f, 13));
  }
  const cv::Mat yellow_f = mask_float(s.yellow);
  const cv::Mat white_f = mask_float(s.white);
  for (int k : {5, 21}) out.add("rgb.yellow_" + std::to_string(k), density(yellow_f, k));
  out.add("rgb.yellow_distance", clipped_distance(s.yellow, 60.0f));
  for (int k : {5, 13}) out.add("rgb.white_" + std::to_string(k), density(white_f, k));
  cv::Mat dx, dy;
  implied_direction(s.yellow, s.ax, s.ay, /*left=*/true, 30.0f, dx, dy);
  out.add("rgb.yellow_left_dir_x", dx);
  out.add("rgb.yellow_left_dir_y", dy);
}

void semantic_features(const TileInput& t, Shared& s, FeatureSink& out) {
  for (const ClassGroup& g : class_groups()) {
    cv::Mat member = cv::Mat::zeros(t.semantic.size(), CV_8U);
    for (int id : g.ids) member |= (t.semantic == id);
    const cv::Mat member_f = mask_float(member);
    for (int k : {5, 21}) {
      out.add("semantic." + std::string(g.name) + "_" + std::to_string(k), valid_mean(member_f, s.sem_valid_f, k));
    }
  }
  out.add("semantic.coverage_21", density(s.sem_valid_f, 21));
  out.add("semantic.marking_distance", clipped_distance(s.sem_marking, 40.0f));
  out.add("semantic.edge_distance", clipped_distance(s.road_edge, 60.0f));
  cv::Mat dx, dy;
  implied_direction(s.road_edge, s.ax, s.ay, /*left=*/false, 60.0f, dx, dy);
  out.add("semantic.edge_right_dir_x", dx);
  out.add("semantic.edge_right_dir_y", dy);
}

void vehicle_features(const TileInput& t, FeatureSink& out) {
  // Heading h = clockwise bearing from north / 2π → map-frame unit vector (sin, cos).
  cv::Mat present = cv::Mat::zeros(t.vehicle.size(), CV_32F);
  cv::Mat cx = cv::Mat::zeros(t.vehicle.size(), CV_32F), cy = cv::Mat::zeros(t.vehicle.size(), CV_32F);
  {
    for (int v = 0; v < t.vehicle.rows; ++v) {
      for (int u = 0; u < t.vehicle.cols; ++u) {
        const float h = t.vehicle.at<float>(v, u);
        if (!(h >= 0.0f)) continue;
        const double bearing = 2.0 * M_PI * h;
        present.at<float>(v, u) = 1.0f;
        cx.at<float>(v, u) = static_cast<float>(std::sin(bearing));
        cy.at<float>(v, u) = static_cast<float>(std::cos(bearing));
      }
    }
  }
  out.add("vehicle.present", present);
  for (int k : {9, 31, 81}) {
    const std::string ks = std::to_string(k);
    cv::Mat count, sx, sy;
    {
      cv::boxFilter(present, count, CV_32F, {k, k}, {-1, -1}, false, cv::BORDER_CONSTANT);
      cv::boxFilter(cx, sx, CV_32F, {k, k}, {-1, -1}, false, cv::BORDER_CONSTANT);
      cv::boxFilter(cy, sy, CV_32F, {k, k}, {-1, -1}, false, cv::BORDER_CONSTANT);
    }
    out.add("vehicle.density_" + ks, cv::Mat(count / static_cast<float>(k * k)));
    out.add("vehicle.heading_x_" + ks, cv::Mat(sx / cv::max(count, 1.0f)));
    out.add("vehicle.heading_y_" + ks, cv::Mat(sy / cv::max(count, 1.0f)));
  }
}

// The prior map near each pixel: how far its nearest centreline is (clipped at 1 and 4 m of
// 0.2 m px) and how much of it lies around (windows of 1.8 and 6.2 m).
void prior_features(const TileInput& t, FeatureSink& out) {
  NSG_CHECK(!t.prior.empty(), DataError, t.key + ".graph.json", "/prior",
            "a prior graph (the modality prior needs a map-update dataset: generate with splits.preset map-update)");
  const cv::Mat on_line = t.prior != 0;
  out.add("prior.distance_5", clipped_distance(on_line, 5.0f));
  out.add("prior.distance_20", clipped_distance(on_line, 20.0f));
  const cv::Mat line_f = mask_float(on_line);
  out.add("prior.density_9", density(line_f, 9));
  out.add("prior.density_31", density(line_f, 31));
}

Shared shared_maps(const TileInput& t, const Modalities& m) {
  Shared s;
  cv::Mat structure = cv::Mat::zeros(t.lidar.size(), CV_32F);
  if (m.lidar) {
    s.lidar_valid_f = mask_float(t.coverage & 1);
    const cv::Mat intensity = as_float(t.lidar, 1.0 / 255.0);
    // Paint is brighter than the asphalt around it; relative, so the sensor's intensity
    // scale does not matter.
    const cv::Mat local = valid_mean(intensity, s.lidar_valid_f, 31);
    s.paint = ((intensity - local) > 0.12f) & ((t.coverage & 1) != 0);
    structure += mask_float(s.paint);
  }
  if (m.rgb) {
    s.rgb_valid_f = mask_float(t.coverage & 2);
    std::vector<cv::Mat> ch;
    cv::split(t.rgb, ch);
    cv::Mat r, g, b;
    ch[0].convertTo(r, CV_32S);
    ch[1].convertTo(g, CV_32S);
    ch[2].convertTo(b, CV_32S);
    s.yellow = (r > 150) & (g > 120) & (b < 100) & ((r - b) > 90);
    s.white = (ch[0] > 170) & (ch[1] > 170) & (ch[2] > 170);
    structure += mask_float(s.yellow) + mask_float(s.white);
  }
  if (m.semantic) {
    s.sem_valid_f = mask_float(t.coverage & 4);
    s.sem_marking = (t.semantic == 1);
    s.road_edge = (t.semantic == 3) | (t.semantic == 4) | (t.semantic == 5) | (t.semantic == 6) | (t.semantic == 7);
    structure += mask_float(s.sem_marking);
  }
  if (!m.lidar && !m.rgb && !m.semantic) structure = as_float(t.vehicle >= 0.0f, 1.0 / 255.0);
  s.orientation = structure_orientation(structure, 1.5, 6.0);
  axis_from_doubled(s.orientation, s.ax, s.ay);
  return s;
}

cv::Mat support_mask(const TileInput& t, const Modalities& m) {
  cv::Mat any = cv::Mat::zeros(t.lidar.size(), CV_8U);
  if (m.lidar) any |= (t.coverage & 1);
  if (m.rgb) any |= (t.coverage & 2);
  if (m.semantic) any |= (t.coverage & 4);
  if (m.vehicle) any |= (t.vehicle >= 0.0f);
  if (m.prior && !t.prior.empty()) any |= t.prior;
  cv::Mat grown;
  cv::dilate(any != 0, grown, cv::getStructuringElement(cv::MORPH_RECT, {9, 9}));
  return grown != 0;
}

void collect(const TileInput& t, const Modalities& m, FeatureSink& out) {
  Shared s = shared_maps(t, m);
  if (m.lidar) lidar_features(t, s, out);
  orientation_features(s, out);
  if (m.rgb) rgb_features(t, s, out);
  if (m.semantic) semantic_features(t, s, out);
  if (m.vehicle) vehicle_features(t, out);
  if (m.prior) prior_features(t, out);
}

TileInput empty_tile(int size_px) {
  TileInput t;
  t.lidar = cv::Mat::zeros(size_px, size_px, CV_8U);
  t.rgb = cv::Mat::zeros(size_px, size_px, CV_8UC3);
  t.semantic = cv::Mat(size_px, size_px, CV_8U, cv::Scalar(255));
  t.vehicle = cv::Mat(size_px, size_px, CV_32F, cv::Scalar(-1.0f));
  t.coverage = cv::Mat::zeros(size_px, size_px, CV_8U);
  t.prior = cv::Mat::zeros(size_px, size_px, CV_8U);
  return t;
}

}  // namespace

Modalities Modalities::parse(const std::string& list) {
  Modalities m{false, false, false, false, false};
  std::stringstream in(list);
  std::string item;
  while (std::getline(in, item, ',')) {
    item = std::string(trim(item));
    if (item == "all") m.lidar = m.rgb = m.semantic = m.vehicle = true;
    else if (item == "lidar") m.lidar = true;
    else if (item == "rgb") m.rgb = true;
    else if (item == "semantic" || item == "semantics") m.semantic = true;
    else if (item == "vehicle" || item == "vehicles") m.vehicle = true;
    else if (item == "prior") m.prior = true;
    else
      throw ConfigError("", "--modalities",
                        "a comma-separated subset of lidar, rgb, semantic, vehicle, prior (got '" + item + "')");
  }
  m.validate();
  return m;
}

std::string Modalities::to_string() const {
  std::string s;
  auto add = [&s](bool on, const char* name) {
    if (!on) return;
    if (!s.empty()) s += ",";
    s += name;
  };
  add(lidar, "lidar");
  add(rgb, "rgb");
  add(semantic, "semantic");
  add(vehicle, "vehicle");
  add(prior, "prior");
  return s;
}

void Modalities::validate() const {
  NSG_CHECK(any(), ConfigError, "", "modalities", "at least one of lidar, rgb, semantic, vehicle, prior");
}

std::vector<std::string> feature_names(const Modalities& modalities) {
  // The names do not depend on the data: compute them on a tiny empty tile.
  FeatureSink sink;
  collect(empty_tile(16), modalities, sink);
  return sink.names;
}

FeatureMaps compute_features(const TileInput& tile, const Modalities& modalities) {
  modalities.validate();
  FeatureSink sink;
  collect(tile, modalities, sink);
  FeatureMaps f;
  f.names = sink.names;
  // Interleave the maps into one multi-channel image: rows = pixels, columns = features.
  const int pixels = tile.lidar.rows * tile.lidar.cols;
  cv::Mat interleaved;
  cv::merge(sink.maps, interleaved);
  f.values = interleaved.reshape(1, pixels);
  f.support = support_mask(tile, modalities);
  return f;
}

}  // namespace nsg::model

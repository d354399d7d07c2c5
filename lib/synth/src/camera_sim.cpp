// Camera simulation: one ray per pixel centre through the SceneRaycaster; textured ground,
// face-shaded boxes, poles and a sky gradient, plus the matching semantic class image.
#include "nsg/synth/camera_sim.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "nsg/core/error.h"

namespace nsg::synth {
namespace {

using Rgb = std::array<uint8_t, 3>;

void require(bool ok, const char* record, const std::string& expected) {
  if (!ok) throw ConfigError("", record, expected);
}

// Rounds half up after clamping to 0..255 (cheaper than llround per channel).
uint8_t clamp_byte(double v) { return static_cast<uint8_t>(std::clamp(v, 0.0, 255.0) + 0.5); }

// Texture amplitude (±, 0..255 scale) of each ground material.
double texture_amplitude(GroundMaterial material) {
  switch (material) {
    case GroundMaterial::kAsphalt: return 6.0;
    case GroundMaterial::kTerrain: return 14.0;
    case GroundMaterial::kVegetation: return 18.0;
    case GroundMaterial::kSidewalk: return 5.0;
    case GroundMaterial::kCurbTop: return 4.0;
    default: return 3.0;
  }
}

// A fixed texture in world coordinates (10 cm cells), so it does not crawl between frames:
// a value in [−1, 1] from a hash of the cell.
double world_texture(const Eigen::Vector3d& p) {
  const auto ix = static_cast<int64_t>(std::floor(p.x() * 10.0));
  const auto iy = static_cast<int64_t>(std::floor(p.y() * 10.0));
  const uint64_t h = mix64(static_cast<uint64_t>(ix) * 0x9E3779B97F4A7C15ULL ^ mix64(static_cast<uint64_t>(iy)));
  return static_cast<double>(h >> 11) * (2.0 / 9007199254740992.0) - 1.0;
}

Rgb sky_rgb(const Eigen::Vector3d& unit_dir) {
  const Rgb horizon{200, 214, 228}, zenith{62, 120, 196}, below{176, 182, 188};
  if (unit_dir.z() < 0.0) return below;  // beyond the world's edge, looking down
  const double s = std::sqrt(std::min(1.0, unit_dir.z() * 3.0));
  Rgb c;
  for (int k = 0; k < 3; ++k) c[k] = clamp_byte(horizon[k] + (zenith[k] - horizon[k]) * s);
  return c;
}

// Lambert shading with a fixed sun, a weak fill light and ambient light, so faces differ
// by orientation even when none of them faces the sun (factor in [0.45, 1]).
Rgb shade(const Rgb& base, const Eigen::Vector3d& normal) {
  static const Eigen::Vector3d sun = Eigen::Vector3d(-0.45, -0.35, 0.82).normalized();
  static const Eigen::Vector3d fill = Eigen::Vector3d(0.6, 0.8, 0.0);
  const double f = 0.45 + 0.45 * std::max(0.0, normal.dot(sun)) + 0.05 * (1.0 + normal.dot(fill));
  return {clamp_byte(base[0] * f), clamp_byte(base[1] * f), clamp_byte(base[2] * f)};
}

// Classes a segmentation model plausibly confuses with each class (label noise).
const std::vector<SemanticClass>& confusions(SemanticClass cls) {
  using C = SemanticClass;
  static const std::vector<std::vector<SemanticClass>> table = {
      /* road */ {C::kLaneMarking, C::kSidewalk, C::kCrosswalk},
      /* lane_marking */ {C::kRoad},
      /* crosswalk */ {C::kRoad, C::kLaneMarking},
      /* sidewalk */ {C::kCurb, C::kRoad, C::kTerrain},
      /* curb */ {C::kSidewalk, C::kRoad},
      /* terrain */ {C::kVegetation, C::kSidewalk},
      /* vegetation */ {C::kTerrain, C::kBuilding},
      /* building */ {C::kVegetation, C::kPoleSign},
      /* car */ {C::kTruckBus, C::kRoad},
      /* truck_bus */ {C::kCar},
      /* person */ {C::kTwoWheeler, C::kPoleSign},
      /* two_wheeler */ {C::kPerson, C::kCar},
      /* pole_sign */ {C::kBuilding, C::kVegetation},
      /* sky_other */ {C::kBuilding, C::kVegetation},
  };
  static const std::vector<SemanticClass> none;
  const auto i = static_cast<size_t>(cls);
  return i < table.size() ? table[i] : none;
}

// A class different from `cls` found a little beyond the blob's rim (8 probes from a
// random start direction), or kVoid if the blob sits inside one region.
uint8_t neighbouring_class(const CameraImage& image, int cx, int cy, int radius, uint8_t cls, Rng& rng) {
  static const int kDirs[8][2] = {{1, 0}, {1, 1}, {0, 1}, {-1, 1}, {-1, 0}, {-1, -1}, {0, -1}, {1, -1}};
  const int start = static_cast<int>(rng.uniform_int(uint64_t{8}));
  const int reach = 2 * radius;
  for (int k = 0; k < 8; ++k) {
    const int x = cx + kDirs[(start + k) % 8][0] * reach, y = cy + kDirs[(start + k) % 8][1] * reach;
    if (x < 0 || y < 0 || x >= image.width_px || y >= image.height_px) continue;
    const uint8_t other = image.classes[static_cast<size_t>(y) * image.width_px + x];
    if (other != cls && other < 14) return other;
  }
  return static_cast<uint8_t>(SemanticClass::kVoid);
}

// Flips round(rate · N) pixels of `classes` in disc-shaped blobs restricted to the blob
// centre's class region, like a segmentation model's errors: mostly near region borders
// (the blob takes the neighbouring region's class), sometimes inside a region (a class the
// model plausibly confuses it with, see confusions()).
void add_label_noise(CameraImage& image, double rate, Rng& rng) {
  const int w = image.width_px, h = image.height_px;
  const size_t n = image.classes.size();
  const auto target = static_cast<size_t>(std::llround(rate * static_cast<double>(n)));
  if (target == 0) return;
  std::vector<uint8_t> flipped(n, 0);
  size_t done = 0;
  int idle_blobs = 0;  // stops if blobs keep finding nothing to flip
  while (done < target && idle_blobs < 10000) {
    const int cx = static_cast<int>(rng.uniform_int(static_cast<uint64_t>(w)));
    const int cy = static_cast<int>(rng.uniform_int(static_cast<uint64_t>(h)));
    const int radius = static_cast<int>(rng.uniform_int(int64_t{2}, int64_t{14}));
    const size_t centre = static_cast<size_t>(cy) * w + cx;
    const uint8_t cls = image.classes[centre];
    if (flipped[centre]) {
      ++idle_blobs;
      continue;
    }
    uint8_t to = neighbouring_class(image, cx, cy, radius, cls, rng);
    if (to == static_cast<uint8_t>(SemanticClass::kVoid)) {
      const auto& options = confusions(static_cast<SemanticClass>(cls));
      // Interior errors are rarer than border errors.
      if (options.empty() || !rng.bernoulli(0.2)) {
        ++idle_blobs;
        continue;
      }
      to = static_cast<uint8_t>(options[rng.uniform_int(options.size())]);
    }
    size_t blob = 0;
    for (int y = std::max(0, cy - radius); y <= std::min(h - 1, cy + radius) && done < target; ++y) {
      for (int x = std::max(0, cx - radius); x <= std::min(w - 1, cx + radius) && done < target; ++x) {
        if ((x - cx) * (x - cx) + (y - cy) * (y - cy) > radius * radius) continue;
        const size_t i = static_cast<size_t>(y) * w + x;
        if (flipped[i] || image.classes[i] != cls) continue;
        image.classes[i] = to;
        flipped[i] = 1;
        ++done;
        ++blob;
      }
    }
    idle_blobs = blob == 0 ? idle_blobs + 1 : 0;
  }
}

}  // namespace

void CameraSimOptions::validate() const {
  require(width_px > 0 && width_px <= 16384, "width_px", "1..16384 pixels");
  require(height_px > 0 && height_px <= 16384, "height_px", "1..16384 pixels");
  require(std::isfinite(label_noise_rate) && label_noise_rate >= 0.0 && label_noise_rate <= 0.5, "label_noise_rate",
          "a fraction in [0, 0.5]");
  require(std::isfinite(max_depth_m) && max_depth_m > 0.0, "max_depth_m", "a depth > 0 m");
  require(std::isfinite(pixel_noise) && pixel_noise >= 0.0 && pixel_noise <= 64.0, "pixel_noise",
          "an amplitude in [0, 64]");
  raycast.validate();
}

std::array<uint8_t, 3> ground_base_rgb(GroundMaterial material) {
  switch (material) {
    case GroundMaterial::kAsphalt: return {84, 84, 88};
    case GroundMaterial::kPaintWhite: return {232, 232, 226};
    case GroundMaterial::kPaintYellow: return {226, 186, 40};
    case GroundMaterial::kCrosswalkPaint: return {238, 238, 232};
    case GroundMaterial::kSidewalk: return {190, 184, 174};
    case GroundMaterial::kCurbTop: return {160, 160, 156};
    case GroundMaterial::kTerrain: return {118, 112, 64};
    case GroundMaterial::kVegetation: return {58, 112, 44};
  }
  return {128, 128, 128};
}

SemanticClass ground_class(GroundMaterial material) {
  switch (material) {
    case GroundMaterial::kAsphalt: return SemanticClass::kRoad;
    case GroundMaterial::kPaintWhite:
    case GroundMaterial::kPaintYellow: return SemanticClass::kLaneMarking;
    case GroundMaterial::kCrosswalkPaint: return SemanticClass::kCrosswalk;
    case GroundMaterial::kSidewalk: return SemanticClass::kSidewalk;
    case GroundMaterial::kCurbTop: return SemanticClass::kCurb;
    case GroundMaterial::kTerrain: return SemanticClass::kTerrain;
    case GroundMaterial::kVegetation: return SemanticClass::kVegetation;
  }
  return SemanticClass::kVoid;
}

CameraImage render_camera(const SceneSnapshot& scene, const geometry::Rigid3& global_from_camera,
                          const Eigen::Matrix3d& intrinsic, const CameraSimOptions& options, Rng& rng) {
  options.validate();
  const SceneRaycaster caster(scene, options.raycast);
  return render_camera(caster, global_from_camera, intrinsic, options, rng);
}

CameraImage render_camera(const SceneRaycaster& caster, const geometry::Rigid3& global_from_camera,
                          const Eigen::Matrix3d& intrinsic, const CameraSimOptions& options, Rng& rng) {
  options.validate();
  const double det = intrinsic.determinant();
  require(std::isfinite(det) && std::abs(det) > 1e-12 && intrinsic.allFinite(), "intrinsic",
          "an invertible, finite 3x3 camera matrix");
  // The exact inverse of the devkit projection u = (K p).x / z: p ∝ K⁻¹ [u, v, 1].
  const Eigen::Matrix3d k_inv = intrinsic.inverse();
  const Eigen::Vector3d origin = global_from_camera.translation;
  const Eigen::Matrix3d& rotation = global_from_camera.rotation;

  CameraImage image;
  image.width_px = options.width_px;
  image.height_px = options.height_px;
  const size_t n = static_cast<size_t>(options.width_px) * options.height_px;
  image.rgb.resize(3 * n);
  image.classes.resize(n);

  for (int v = 0; v < options.height_px; ++v) {
    for (int u = 0; u < options.width_px; ++u) {
      const Eigen::Vector3d p_cam = k_inv * Eigen::Vector3d(u, v, 1.0);
      const double norm = p_cam.norm();
      const Eigen::Vector3d dir = rotation * (p_cam / norm);
      const double depth_per_m = p_cam.z() / norm;  // camera depth per metre of range
      Rgb rgb;
      SemanticClass cls = SemanticClass::kSkyOther;
      RayHit hit;
      if (depth_per_m > 0.0) hit = caster.cast(origin, dir, options.max_depth_m / depth_per_m);
      if (!hit.hit) {
        rgb = sky_rgb(dir);
      } else if (hit.kind == RayHit::Kind::kGround) {
        const Rgb base = ground_base_rgb(hit.material);
        const double tex = texture_amplitude(hit.material) * world_texture(hit.point_m);
        // Curb faces (vertical steps) are darker than tops.
        const double f = hit.normal.z() > 0.5 ? 1.0 : 0.75;
        for (int k = 0; k < 3; ++k) rgb[k] = clamp_byte(base[k] * f + tex);
        cls = ground_class(hit.material);
      } else {
        rgb = shade(hit.rgb, hit.normal);
        cls = hit.cls;
      }
      const size_t i = static_cast<size_t>(v) * options.width_px + u;
      if (options.pixel_noise > 0.0) {
        const uint64_t bits = rng.next_u64();
        for (int k = 0; k < 3; ++k) {
          const double unit = static_cast<double>((bits >> (16 * k)) & 0xFFFF) / 65535.0;
          rgb[k] = clamp_byte(rgb[k] + (2.0 * unit - 1.0) * options.pixel_noise);
        }
      }
      image.rgb[3 * i] = rgb[0];
      image.rgb[3 * i + 1] = rgb[1];
      image.rgb[3 * i + 2] = rgb[2];
      image.classes[i] = static_cast<uint8_t>(cls);
    }
  }
  if (options.label_noise_rate > 0.0) add_label_noise(image, options.label_noise_rate, rng);
  return image;
}

}  // namespace nsg::synth

// The JSON tables of a release (nuScenes v1.0 layout, Python-style JSON), lidarseg.json and
// the detections file. Records are collected per table in the scenes' order and written
// once; every token comes from table_token/fixed_token, so the files do not depend on threads.
#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "nsg/core/rng.h"
#include "nsg/core/strings.h"
#include "release_writer.h"

namespace nsg::synth::release_detail {

using geometry::Pose2;
using geometry::Quaternion;

// The records of every table, collected before any is written.
struct ReleaseTables {
  PyJson sensor = PyJson::array(), category = PyJson::array(), attribute = PyJson::array(),
         visibility = PyJson::array();
  PyJson scene = PyJson::array(), sample = PyJson::array(), sample_data = PyJson::array(), ego_pose = PyJson::array(),
         calibrated = PyJson::array(), log = PyJson::array(), sample_ann = PyJson::array(), instance = PyJson::array();
  std::vector<std::string> log_tokens;
};

namespace {

constexpr double kPi = 3.141592653589793;

PyJson vec3(const std::array<double, 3>& v) { return PyJson::array({v[0], v[1], v[2]}); }
PyJson quat(const Quaternion& q) { return PyJson::array({q.w, q.x, q.y, q.z}); }

// ---- fixed tables -------------------------------------------------------------------------
struct CategorySpec {
  const char* name;
  const char* description;
  int index;
};
// The fixed table of the nuScenes categories with the lidarseg classes: data, one record each.
const std::vector<CategorySpec>& categories() {
  static const std::vector<CategorySpec> k = {
      {"human.pedestrian.adult", "Adult subcategory.", 2},
      {"human.pedestrian.child", "Child subcategory.", 3},
      {"human.pedestrian.wheelchair", "Wheelchairs. If a person is in the wheelchair, include in the annotation.", 8},
      {"human.pedestrian.stroller", "Strollers. If a person is in the stroller, include in the annotation.", 7},
      {"human.pedestrian.personal_mobility",
       "A small electric or self-propelled vehicle, e.g. skateboard, segway, or scooters.", 5},
      {"human.pedestrian.police_officer", "Police officer.", 6},
      {"human.pedestrian.construction_worker", "Construction worker", 4},
      {"animal", "All animals, e.g. cats, rats, dogs, deer, birds.", 1},
      {"vehicle.car",
       "Vehicle designed primarily for personal use, e.g. sedans, hatch-backs, wagons, vans, mini-vans, SUVs and "
       "jeeps.",
       17},
      {"vehicle.motorcycle",
       "Gasoline or electric powered 2-wheeled vehicle designed to move rapidly (at the speed of standard cars) on the "
       "road surface.",
       21},
      {"vehicle.bicycle",
       "Human or electric powered 2-wheeled vehicle designed to travel at lower speeds either on road surface, "
       "sidewalks or bike paths.",
       14},
      {"vehicle.bus.bendy", "Bendy bus subcategory. Annotate each section of the bendy bus individually.", 15},
      {"vehicle.bus.rigid", "Rigid bus subcategory.", 16},
      {"vehicle.truck",
       "Vehicles primarily designed to haul cargo including pick-ups, lorrys, trucks and semi-tractors.", 23},
      {"vehicle.construction",
       "Vehicles primarily designed for construction. Typically very slow moving or stationary.", 18},
      {"vehicle.emergency.ambulance", "All types of ambulances.", 19},
      {"vehicle.emergency.police", "All types of police vehicles including police bicycles and motorcycles.", 20},
      {"vehicle.trailer", "Any vehicle trailer, both for trucks, cars and bikes.", 22},
      {"movable_object.barrier", "Temporary road barrier placed in the scene in order to redirect traffic.", 9},
      {"movable_object.trafficcone", "All types of traffic cone.", 12},
      {"movable_object.pushable_pullable",
       "Objects that a pedestrian may push or pull, e.g. dolleys, wheel barrows, garbage-bins.", 11},
      {"movable_object.debris",
       "Movable object that is left on the driveable surface that is too large to be driven over safely.", 10},
      {"static_object.bicycle_rack", "Area or device intended to park or secure the bicycles in a row.", 13},
      // The classes nuScenes-lidarseg adds (its category.json has all 32, each with index).
      {"noise",
       "Any lidar return that does not correspond to a physical object, such as dust, vapor, noise, fog, raindrops, "
       "smoke and reflections.",
       0},
      {"flat.driveable_surface",
       "All paved or unpaved surfaces that a car can drive on with no concern of traffic rules.", 24},
      {"flat.other",
       "All other forms of horizontal ground-level structures that do not belong to any of driveable_surface, curb, "
       "sidewalk and terrain. Includes elevated parts of traffic islands, delimiters, rail tracks, stairs with at most "
       "3 steps and larger bodies of water - lakes, rivers.",
       25},
      {"flat.sidewalk",
       "Sidewalk, pedestrian walkways, bike paths, etc. Part of the ground designated for pedestrians or cyclists. "
       "Sidewalks do **not** have to be next to a road.",
       26},
      {"flat.terrain",
       "Natural horizontal surfaces such as ground level horizontal vegetation (< 20 cm tall), grass, rolling hills, "
       "soil, sand and gravel.",
       27},
      {"static.manmade",
       "Includes man-made structures but not limited to: buildings, walls, guard rails, fences, poles, drainages, "
       "hydrants, flags, banners, street signs, electric circuit boxes, traffic lights, parking meters and stairs with "
       "more than 3 steps.",
       28},
      {"static.other",
       "Points in the background that are not distinguishable. Or objects that do not match any of the above labels.",
       29},
      {"static.vegetation",
       "Any vegetation in the frame that is higher than the ground, including bushes, plants, potted plants, trees, "
       "etc. Only tall grass (> 20cm) is part of this, ground level grass is part of `flat.terrain`.",
       30},
      {"vehicle.ego",
       "The vehicle on which the cameras, radar and lidar are mounted, that is sometimes visible at the bottom of the "
       "image.",
       31},
  };
  return k;
}
const std::vector<std::pair<const char*, const char*>>& attributes() {
  static const std::vector<std::pair<const char*, const char*>> k = {
      {"vehicle.moving", "Vehicle is moving."},
      {"vehicle.stopped", "Vehicle, with a driver/rider in/on it, is currently stationary but has an intent to move."},
      {"vehicle.parked", "Vehicle is stationary (usually for longer duration) with no immediate intent to move."},
      {"cycle.with_rider", "There is a rider on the bicycle or motorcycle."},
      {"cycle.without_rider", "There is NO rider on the bicycle or motorcycle."},
      {"pedestrian.sitting_lying_down", "The human is sitting or lying down."},
      {"pedestrian.standing", "The human is standing."},
      {"pedestrian.moving", "The human is moving."},
  };
  return k;
}

const std::vector<std::string>& official_scene_names() {
  static const std::vector<std::string> k = {"scene-0061", "scene-0553", "scene-0655", "scene-0757", "scene-0796",
                                             "scene-1077", "scene-1094", "scene-1100", "scene-0103", "scene-0916"};
  return k;
}
std::string scene_name(int i) {
  if (i < static_cast<int>(official_scene_names().size())) return official_scene_names()[static_cast<size_t>(i)];
  return strprintf("scene-%04d", 2000 + i);  // beyond the official mini names
}

// The fixed tables: the same records in every synthetic release.
void add_fixed_tables(ReleaseTables& tables) {
  for (const SensorSpec& sp : sensor_specs())
    tables.sensor.push_back(PyJson{{"token", sp.token}, {"channel", sp.channel}, {"modality", sp.modality}});
  for (const CategorySpec& c : categories())
    tables.category.push_back(PyJson{{"token", fixed_token("category", c.name)},
                                     {"name", c.name},
                                     {"description", c.description},
                                     {"index", c.index}});
  for (const auto& [name, desc] : attributes())
    tables.attribute.push_back(
        PyJson{{"token", fixed_token("attribute", name)}, {"name", name}, {"description", desc}});
  const char* levels[] = {"v0-40", "v40-60", "v60-80", "v80-100"};
  const char* vis_desc[] = {
      "visibility of whole object is between 0 and 40%", "visibility of whole object is between 40 and 60%",
      "visibility of whole object is between 60 and 80%", "visibility of whole object is between 80 and 100%"};
  for (int i = 0; i < 4; ++i)
    tables.visibility.push_back(
        PyJson{{"description", vis_desc[i]}, {"token", std::to_string(i + 1)}, {"level", levels[i]}});
}

}  // namespace

// ---- tables -----------------------------------------------------------------------------

// nuScenes-lidarseg's layout: lidarseg/<version>/<sample_data token>_lidarseg.bin.
std::string ReleaseWriter::lidarseg_filename(const Frame& f) const {
  return "lidarseg/" + cfg_.version + "/" + f.token + "_lidarseg.bin";
}

// lidarseg.json: one record per key-frame LIDAR_TOP sweep, its token the sweep's
// sample_data token (the devkit looks records up by it), in sample_data order.
void ReleaseWriter::write_lidarseg_table() {
  PyJson lidarseg = PyJson::array();
  for (const SceneRun& s : scenes_) {
    auto it = s.frames.find("LIDAR_TOP");
    if (it == s.frames.end()) continue;
    for (const Frame& f : it->second) {
      if (!f.key) continue;
      lidarseg.push_back(
          PyJson{{"token", f.token}, {"sample_data_token", f.token}, {"filename", lidarseg_filename(f)}});
    }
  }
  write_table("lidarseg", lidarseg);
}

void ReleaseWriter::write_table(const std::string& name, const PyJson& records) {
  put(cfg_.version + "/" + name + ".json", py_json_dump(records, PyJsonStyle::kIndent0));
}

std::string ReleaseWriter::visibility_of(int pts) {
  if (pts == 0) return "1";
  if (pts < 5) return "2";
  if (pts < 20) return "3";
  return "4";
}

std::string ReleaseWriter::attribute_of(const Agent& a, double t) const {
  if (a.kind == Agent::Kind::kParked) return "vehicle.parked";
  if (a.kind == Agent::Kind::kPedestrian) return "pedestrian.moving";
  return a.moving_at(t) ? "vehicle.moving" : "vehicle.stopped";
}

// log, scene and sample records of one scene.
void ReleaseWriter::add_log_and_scene(const SceneRun& s, ReleaseTables& tables) const {
  tables.log.push_back(PyJson{{"token", s.log_token},
                              {"logfile", s.logfile},
                              {"vehicle", s.logfile.substr(0, 4)},
                              {"date_captured", s.date},
                              {"location", cfg_.location}});
  tables.log_tokens.push_back(s.log_token);
  tables.scene.push_back(
      PyJson{{"token", s.token},
             {"log_token", s.log_token},
             {"nbr_samples", static_cast<int>(s.samples.size())},
             {"first_sample_token", s.samples.front().token},
             {"last_sample_token", s.samples.back().token},
             {"name", scene_name(s.index)},
             {"description",
              "synthetic city drive, " + std::string(cfg_.right_hand_traffic() ? "right" : "left") + "-hand traffic"}});
  for (size_t i = 0; i < s.samples.size(); ++i) {
    tables.sample.push_back(PyJson{{"token", s.samples[i].token},
                                   {"timestamp", s.samples[i].timestamp},
                                   {"prev", i == 0 ? "" : s.samples[i - 1].token},
                                   {"next", i + 1 == s.samples.size() ? "" : s.samples[i + 1].token},
                                   {"scene_token", s.token}});
  }
}

// calibrated_sensor records of one scene (one per sensor; intrinsics for the cameras).
void ReleaseWriter::add_calibrated_sensors(const SceneRun& s, ReleaseTables& tables) const {
  for (const SensorSpec& sp : sensor_specs()) {
    PyJson k = PyJson::array();
    if (sp.modality == "camera") {
      const Eigen::Matrix3d m = intrinsic_for(sp, cfg_.camera);
      for (int r = 0; r < 3; ++r) k.push_back(PyJson::array({m(r, 0), m(r, 1), m(r, 2)}));
    }
    tables.calibrated.push_back(PyJson{{"token", s.calib_tokens.at(sp.channel)},
                                       {"sensor_token", sp.token},
                                       {"translation", vec3(sp.translation)},
                                       {"rotation", quat(sp.rotation)},
                                       {"camera_intrinsic", k}});
  }
}

// sample_data and ego_pose records of one scene: one of each per frame, channel by channel.
void ReleaseWriter::add_sample_data(const SceneRun& s, ReleaseTables& tables) {
  for (const SensorSpec& sp : sensor_specs()) {
    auto it = s.frames.find(sp.channel);
    if (it == s.frames.end()) continue;
    const std::vector<Frame>& frames = it->second;
    for (size_t j = 0; j < frames.size(); ++j) {
      const Frame& f = frames[j];
      const bool cam = sp.modality == "camera";
      tables.sample_data.push_back(PyJson{{"token", f.token},
                                          {"sample_token", s.samples[static_cast<size_t>(f.sample)].token},
                                          {"ego_pose_token", f.token},
                                          {"calibrated_sensor_token", s.calib_tokens.at(sp.channel)},
                                          {"timestamp", f.timestamp},
                                          {"fileformat", cam ? "jpg" : "pcd"},
                                          {"is_key_frame", f.key},
                                          {"height", cam ? cfg_.camera.height_px : 0},
                                          {"width", cam ? cfg_.camera.width_px : 0},
                                          {"filename", f.filename},
                                          {"prev", j == 0 ? "" : frames[j - 1].token},
                                          {"next", j + 1 == frames.size() ? "" : frames[j + 1].token}});
      const Pose2 p = s.plan.ego_pose_at(seconds_since(s, f.timestamp));
      tables.ego_pose.push_back(PyJson{{"token", f.token},
                                       {"timestamp", f.timestamp},
                                       {"rotation", quat(geometry::quaternion_from_yaw(p.yaw))},
                                       {"translation", PyJson::array({p.x, p.y, 0.0})}});
      ++summary_.sample_data;
    }
  }
}

// Instances: one per agent with annotations in this scene; annotations chained.
void ReleaseWriter::add_instances(const SceneRun& s, ReleaseTables& tables) {
  std::map<int, std::vector<std::pair<size_t, const AnnotationPlan*>>> by_agent;
  for (size_t i = 0; i < s.samples.size(); ++i)
    for (const AnnotationPlan& ap : s.samples[i].anns) by_agent[ap.agent].push_back({i, &ap});
  for (const auto& [agent_idx, anns] : by_agent) {
    const Agent& agent = s.plan.agents[static_cast<size_t>(agent_idx)];
    const std::string inst =
        table_token(seed_, "instance", static_cast<uint64_t>(s.index), static_cast<uint64_t>(agent_idx));
    tables.instance.push_back(PyJson{{"token", inst},
                                     {"category_token", fixed_token("category", agent.category)},
                                     {"nbr_annotations", static_cast<int>(anns.size())},
                                     {"first_annotation_token", anns.front().second->token},
                                     {"last_annotation_token", anns.back().second->token}});
    for (size_t k = 0; k < anns.size(); ++k) {
      const auto& [si, ap] = anns[k];
      const SceneBox& b = ap->box;
      const double t = seconds_since(s, s.samples[si].timestamp);
      tables.sample_ann.push_back(
          PyJson{{"token", ap->token},
                 {"sample_token", s.samples[si].token},
                 {"instance_token", inst},
                 {"visibility_token", visibility_of(ap->num_lidar_pts)},
                 {"attribute_tokens", PyJson::array({fixed_token("attribute", attribute_of(agent, t))})},
                 {"translation", PyJson::array({b.center_m.x(), b.center_m.y(), b.center_m.z()})},
                 {"size", PyJson::array({b.width_m, b.length_m, b.height_m})},
                 {"rotation", quat(geometry::quaternion_from_yaw(b.yaw_rad))},
                 {"prev", k == 0 ? "" : anns[k - 1].second->token},
                 {"next", k + 1 == anns.size() ? "" : anns[k + 1].second->token},
                 {"num_lidar_pts", ap->num_lidar_pts},
                 {"num_radar_pts", 0}});
      ++summary_.annotations;
    }
    ++summary_.instances;
  }
}

void ReleaseWriter::write_tables() {
  ReleaseTables tables;
  add_fixed_tables(tables);
  for (const SceneRun& s : scenes_) {
    add_log_and_scene(s, tables);
    add_calibrated_sensors(s, tables);
    add_sample_data(s, tables);
    add_instances(s, tables);
    summary_.samples += static_cast<int>(s.samples.size());
  }
  PyJson map = PyJson::array();
  const std::string map_token = semantic_prior_token(cfg_.location);
  map.push_back(PyJson{{"category", "semantic_prior"},
                       {"token", map_token},
                       {"filename", "maps/" + map_token + ".png"},
                       {"log_tokens", tables.log_tokens}});
  write_table("attribute", tables.attribute);
  write_table("calibrated_sensor", tables.calibrated);
  write_table("category", tables.category);
  write_table("ego_pose", tables.ego_pose);
  write_table("instance", tables.instance);
  write_table("log", tables.log);
  write_table("map", map);
  write_table("sample", tables.sample);
  write_table("sample_annotation", tables.sample_ann);
  write_table("sample_data", tables.sample_data);
  write_table("scene", tables.scene);
  write_table("sensor", tables.sensor);
  write_table("visibility", tables.visibility);
  if (cfg_.lidar.lidarseg) write_lidarseg_table();
}

// ---- detections -------------------------------------------------------------------------

const char* ReleaseWriter::detection_name(const std::string& category) {
  if (category == "vehicle.car") return "car";
  if (category == "vehicle.truck") return "truck";
  if (category == "vehicle.bus.rigid" || category == "vehicle.bus.bendy") return "bus";
  if (category.rfind("human.pedestrian.", 0) == 0) return "pedestrian";
  return nullptr;
}

PyJson ReleaseWriter::detection_box(const std::string& sample_token, const SceneBox& b,
                                    const std::array<double, 2>& velocity, const std::string& name, double score,
                                    const std::string& attr) {
  return PyJson{{"sample_token", sample_token},
                {"translation", PyJson::array({b.center_m.x(), b.center_m.y(), b.center_m.z()})},
                {"size", PyJson::array({b.width_m, b.length_m, b.height_m})},
                {"rotation", quat(geometry::quaternion_from_yaw(b.yaw_rad))},
                {"velocity", PyJson::array({velocity[0], velocity[1]})},
                {"detection_name", name},
                {"detection_score", score},
                {"attribute_name", attr}};
}

void ReleaseWriter::write_detections() {
  const DetectionsConfig& dc = cfg_.detections;
  PyJson results = PyJson::object();
  for (const SceneRun& s : scenes_) {
    for (size_t i = 0; i < s.samples.size(); ++i) {
      const SampleRec& smp = s.samples[i];
      Rng rng(seed_, mix64(0x646574ULL ^ hash_string(smp.token.data(), smp.token.size())));
      const double t = seconds_since(s, smp.timestamp);
      PyJson boxes = PyJson::array();
      for (const AnnotationPlan& ap : smp.anns) {
        const Agent& agent = s.plan.agents[static_cast<size_t>(ap.agent)];
        const char* name = detection_name(agent.category);
        if (!name || rng.bernoulli(dc.miss_rate)) continue;
        SceneBox b = ap.box;
        b.center_m.x() += rng.normal(0.0, dc.position_noise_m);
        b.center_m.y() += rng.normal(0.0, dc.position_noise_m);
        b.yaw_rad = geometry::wrap_angle_devkit(b.yaw_rad + rng.normal(0.0, dc.yaw_noise_rad));
        const double speed = agent.moving_at(t) && agent.kind == Agent::Kind::kMoving ? agent.speed_mps : 0.0;
        const double yaw = ap.box.yaw_rad;
        const double score = std::clamp(rng.normal(dc.score_true_mean, 0.1), 0.01, 1.0);
        boxes.push_back(detection_box(smp.token, b, {speed * std::cos(yaw), speed * std::sin(yaw)}, name, score,
                                      attribute_of(agent, t)));
      }
      // False positives: cars scattered around the ego.
      const Pose2 ego = s.plan.ego_pose_at(t);
      int n_fp = static_cast<int>(dc.false_positives_per_sample);
      if (rng.bernoulli(dc.false_positives_per_sample - n_fp)) ++n_fp;
      for (int k = 0; k < n_fp; ++k) {
        SceneBox b;
        const double r = rng.uniform(5.0, 45.0), a = rng.uniform(-kPi, kPi);
        b.center_m = {ego.x + r * std::cos(a), ego.y + r * std::sin(a), 0.8};
        b.yaw_rad = rng.uniform(-kPi, kPi);
        b.length_m = 4.5;
        b.width_m = 1.9;
        b.height_m = 1.6;
        const double score = std::clamp(rng.normal(dc.score_false_mean, 0.1), 0.01, 1.0);
        boxes.push_back(detection_box(smp.token, b, {0.0, 0.0}, "car", score, "vehicle.parked"));
      }
      results[smp.token] = boxes;
    }
  }
  PyJson root{{"meta", PyJson{{"use_camera", false},
                              {"use_lidar", true},
                              {"use_radar", false},
                              {"use_map", false},
                              {"use_external", false}}},
              {"results", results}};
  put("detections/" + dc.name + ".json", py_json_dump(root, PyJsonStyle::kCompact));
}

}  // namespace nsg::synth::release_detail

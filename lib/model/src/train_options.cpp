// The declarations of the reference model's options: every key's type, unit, range and
// description in one place, and the validate() of each options struct that runs them.
#include "nsg/model/train_options.h"

#include <map>
#include <mutex>

#include "nsg/core/error.h"

namespace nsg::model {
namespace {

using options::Json;
using options::OrderedJson;
using options::Range;
using options::Spec;
using options::Table;

const Range kOpenUnit{0.0, 1.0, true, true, {}};  // (0, 1)

// The forest named `name` ("centre_forest", as the model file names it).
const Table<ForestOptions>& forest_table(const std::string& name) {
  static std::mutex mutex;
  static std::map<std::string, Table<ForestOptions>> tables;
  const std::lock_guard<std::mutex> lock(mutex);
  auto it = tables.find(name);
  if (it != tables.end()) return it->second;
  Table<ForestOptions>& t = tables[name];
  t.integer(name + ".trees", &ForestOptions::trees).range(options::between(1, 1000)).help("Trees of the forest");
  t.integer(name + ".max_depth", &ForestOptions::max_depth).range(options::between(1, 40)).help("Depth of a tree");
  t.integer(name + ".min_samples", &ForestOptions::min_samples)
      .range(options::at_least(1))
      .help("Fewest training samples in a leaf");
  return t;
}

const Table<AnchorOptions>& anchor_table() {
  static const Table<AnchorOptions> table = [] {
    Table<AnchorOptions> t;
    t.number("anchors.target_sigma_px", &AnchorOptions::target_sigma_px)
        .unit("px")
        .range(options::above_up_to(0, 20))
        .help("Width of the anchor score's training target around each GT node (b2, graph)");
    t.number("anchors.smooth_sigma_px", &AnchorOptions::smooth_sigma_px)
        .unit("px")
        .range(options::between(0, 10))
        .help("Gaussian on the score map before anchors are picked");
    t.number("anchors.min_score", &AnchorOptions::min_score)
        .range(kOpenUnit)
        .help("Candidates scoring below are not anchors");
    t.number("anchors.nms_radius_px", &AnchorOptions::nms_radius_px)
        .unit("px")
        .range(options::between(1, 64))
        .help("No two anchors closer than this");
    t.integer("anchors.neighbours", &AnchorOptions::neighbours)
        .range(options::between(1, 8))
        .help("b2: each anchor joined to this many nearest anchors");
    return t;
  }();
  return table;
}

const Table<PairOptions>& pair_table() {
  static const Table<PairOptions> table = [] {
    Table<PairOptions> t;
    t.number("pairs.radius_px", &PairOptions::radius_px)
        .unit("px")
        .range(options::between(2, 128))
        .help("Candidate pairs: anchors at most this far apart (graph)");
    t.number("pairs.min_connection_score", &PairOptions::min_connection_score)
        .range(options::between(0, 1))
        .help("The connection classifier's decision: below, no edge");
    t.number("pairs.label_max_distance_px", &PairOptions::label_max_distance_px)
        .unit("px")
        .range(options::above(0))
        .help("Training labels: anchors farther than this from every GT lane are not projected");
    t.number("pairs.label_max_follow_px", &PairOptions::label_max_follow_px)
        .unit("px")
        .range(options::at_least(0))
        .help("Training labels: connectivity followed this far through lanes without anchors");
    t.integer("pairs.train_tile_every", &PairOptions::train_tile_every)
        .range(options::at_least(1))
        .help("Training pairs come from every k-th training tile");
    return t;
  }();
  return table;
}

const Table<ExtractionOptions>& extraction_table() {
  static const Table<ExtractionOptions> table = [] {
    Table<ExtractionOptions> t;
    skeleton::declare_skeleton_options(t, "extraction.");
    t.number("extraction.min_node_score", &ExtractionOptions::min_node_score)
        .range(options::between(0, 1))
        .help("Nodes scoring below are dropped");
    t.number("extraction.min_edge_score", &ExtractionOptions::min_edge_score)
        .range(options::between(0, 1))
        .help("Edges scoring below are dropped");
    t.number("extraction.max_edge_fraction", &ExtractionOptions::max_edge_fraction)
        .range(options::above_up_to(0, 1.5))
        .help("Longest edge, as a fraction of the tile size");
    t.number("extraction.min_piece_length_px", &ExtractionOptions::min_piece_length_px)
        .unit("px")
        .range(options::at_least(0))
        .help("Connected pieces shorter than this in total edge length are removed");
    t.number("extraction.max_direction_angle_deg", &ExtractionOptions::max_direction_angle_deg)
        .unit("deg")
        .range(options::above_up_to(0, 90))
        .help("Edges further than this from the predicted direction are removed (90 = off)");
    return t;
  }();
  return table;
}

}  // namespace

const Table<ModelOptions>& model_option_table() {
  static const Table<ModelOptions> table = [] {
    Table<ModelOptions> t;
    t.choice("variant", &ModelOptions::variant,
             {{"b1", Variant::kB1}, {"b2", Variant::kB2}, {"graph", Variant::kGraph}})
        .help(
            "Model (the paper's Table II): b1 skeletonized centrelines, b2 anchors joined to their nearest "
            "neighbours, graph anchors joined by a trained has-connection classifier");
    t.shape(
         "modalities",
         "\"all\" (the four sensor layers) or a comma list of lidar, rgb, semantic, vehicle, prior (a map-update "
         "tile's prior graph as a layer)",
         {{"type", "string"}, {"minLength", 1}},
         [](const ModelOptions& o) { return OrderedJson(o.modalities.to_string()); },
         [](ModelOptions& o, const Json& v, const Spec& s) {
           const std::string text = options::read_string(v, s);
           try {
             o.modalities = Modalities::parse(text);
           } catch (const ConfigError&) {
             options::reject(v, s);
           }
         })
        .help("Input layers (the paper's ablation)");
    t.integer("seed", &ModelOptions::seed).range(options::at_least(0)).help("Seed of the pixel sampling");
    t.include(&ModelOptions::centre, forest_table("centre_forest"));
    t.include(&ModelOptions::direction, forest_table("direction_forest"));
    t.include(&ModelOptions::anchor, forest_table("anchor_forest"));
    t.include(&ModelOptions::connection, forest_table("connection_forest"));
    t.number("sigma_px", &ModelOptions::sigma_px)
        .unit("px")
        .range(Range{0.0, 20.0, true, true, {}})
        .help("Width of the soft centreline target exp(-d²/2σ²)");
    const Range samples = options::between(0, 100000);
    t.integer("centre_samples_near", &ModelOptions::centre_samples_near)
        .range(samples)
        .help("Pixels sampled per training tile near a centreline");
    t.integer("centre_samples_around", &ModelOptions::centre_samples_around)
        .range(samples)
        .help("Pixels sampled per training tile around a centreline");
    t.integer("centre_samples_far", &ModelOptions::centre_samples_far)
        .range(samples)
        .help("Pixels sampled per training tile far from any centreline");
    t.integer("direction_samples_lane", &ModelOptions::direction_samples_lane)
        .range(samples)
        .help("Lane pixels sampled per training tile for the direction head");
    t.integer("direction_samples_background", &ModelOptions::direction_samples_background)
        .range(samples)
        .help("Background pixels sampled per training tile for the direction head");
    t.integer("predict_stride_px", &ModelOptions::predict_stride_px)
        .unit("px")
        .range(options::between(1, 4))
        .help("The centreline forest is evaluated every this many pixels and interpolated");
    t.integer("holdout_every", &ModelOptions::holdout_every)
        .range(options::at_least(0))
        .then([](ModelOptions& o) {
          NSG_CHECK(o.holdout_every != 1, ConfigError, "", "holdout_every", "0 (none) or an integer ≥ 2 (got 1)");
        })
        .help("Every k-th tile (manifest order) is held out for the training report (0 = none; else ≥ 2)");
    t.include(&ModelOptions::anchors, anchor_table());
    t.include(&ModelOptions::pairs, pair_table());
    t.include(&ModelOptions::extraction, extraction_table());
    return t;
  }();
  return table;
}

const Table<TrainConfig>& train_option_table() {
  static const Table<TrainConfig> table = [] {
    Table<TrainConfig> t;
    options::schema_version_option(t);
    t.text("split", &TrainConfig::split).non_empty().help("Split of the dataset to train on");
    t.include(&TrainConfig::model, model_option_table());
    return t;
  }();
  return table;
}

OrderedJson train_config_schema() {
  return options::config_schema(
      train_option_table().specs(), "https://nuscenesgraph.org/schemas/v1/train-config.schema.json",
      "NuScenesGraph train config (v1)",
      "Options of `nsgraph train` (the reference model). A file may give any subset of the keys; the others keep "
      "their defaults. Generated from the options' declarations: `nsgraph train --list-options --format schema`.");
}

TrainConfig resolve_train_config(const std::filesystem::path& file, const std::vector<std::string>& settings,
                                 const std::vector<options::FlagValue>& flags, options::Origins* origins) {
  options::Origins local;
  return options::resolve_config(train_option_table(), file, settings, flags, "centre_forest.trees=16",
                                 origins ? *origins : local);
}

void ForestOptions::validate(const std::string& field) const { forest_table(field + "_forest").check(*this); }
void AnchorOptions::validate() const { anchor_table().check(*this); }
void PairOptions::validate() const { pair_table().check(*this); }
void ExtractionOptions::validate() const { extraction_table().check(*this); }
void ModelOptions::validate() const { model_option_table().check(*this); }

}  // namespace nsg::model

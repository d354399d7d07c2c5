// The model file (OpenCV FileStorage YAML, gzip when the name ends in .gz) and the
// submission writer.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <type_traits>

#include "gzip.h"
#include "model_impl.h"
#include "nsg/core/atomic_file.h"
#include "nsg/core/error.h"
#include "nsg/core/version.h"

namespace nsg::model {
namespace {

constexpr const char* kFormat = "nsgraph-lane-model";
constexpr int kFormatVersion = 1;

// A stored number, or `fallback` when the field is absent (files from before it existed).
// An integer field must hold a number within its type: casting 1e308 to int is undefined
// behaviour (found by fuzz_model); the options' own checks judge the value after.
template <typename T>
T value_or(const cv::FileNode& n, T fallback, const std::string& file, const std::string& key) {
  if (n.empty()) return fallback;
  NSG_CHECK(n.isInt() || n.isReal(), ParseError, file, key, "a number");
  const double v = static_cast<double>(n);
  if constexpr (std::is_integral_v<T> && !std::is_same_v<T, bool>) {
    static_assert(sizeof(T) <= 4, "the bounds below are exact in double for 32-bit types only");
    NSG_CHECK(v >= static_cast<double>(std::numeric_limits<T>::min()) &&
                  v <= static_cast<double>(std::numeric_limits<T>::max()),
              ParseError, file, key, "an integer within " + std::string(sizeof(T) == 4 ? "32" : "16") + " bits");
  }
  return static_cast<T>(v);
}

// The named number fields of the option groups, in file order: one list each for the
// writer and the reader, so the two cannot drift apart. f(key, field) per field.
constexpr auto kExtractionFields = [](auto& e, auto&& f) {
  f("threshold", e.threshold);
  f("min_component_px", e.min_component_px);
  f("min_spur_px", e.min_spur_px);
  f("simplify_tolerance_px", e.simplify_tolerance_px);
  f("anchor_spacing_px", e.anchor_spacing_px);
  f("min_node_score", e.min_node_score);
  f("min_edge_score", e.min_edge_score);
  f("max_edge_fraction", e.max_edge_fraction);
  f("smooth_sigma_px", e.smooth_sigma_px);
  f("min_piece_length_px", e.min_piece_length_px);
  f("max_direction_angle_deg", e.max_direction_angle_deg);
};
constexpr auto kAnchorFields = [](auto& a, auto&& f) {
  f("target_sigma_px", a.target_sigma_px);
  f("smooth_sigma_px", a.smooth_sigma_px);
  f("min_score", a.min_score);
  f("nms_radius_px", a.nms_radius_px);
  f("neighbours", a.neighbours);
};
constexpr auto kPairFields = [](auto& p, auto&& f) {
  f("radius_px", p.radius_px);
  f("min_connection_score", p.min_connection_score);
  f("label_max_distance_px", p.label_max_distance_px);
  f("label_max_follow_px", p.label_max_follow_px);
  f("train_tile_every", p.train_tile_every);
};

// `name: { key: value, ... }` from a field list.
template <typename Options, typename Fields>
void write_fields(cv::FileStorage& fs, const char* name, const Options& options, Fields fields) {
  fs << name << "{";
  fields(options, [&](const char* key, const auto& value) { fs << key << value; });
  fs << "}";
}
// The fields of node `n` (the file's `group`) into `options`, each keeping its value when absent.
template <typename Options, typename Fields>
void read_fields(const cv::FileNode& n, Options& options, Fields fields, const std::string& file,
                 const std::string& group) {
  fields(options, [&](const char* key, auto& value) { value = value_or(n[key], value, file, group + "/" + key); });
}

void write_forest_options(cv::FileStorage& fs, const std::string& name, const ForestOptions& f) {
  fs << name << "{"
     << "trees" << f.trees << "max_depth" << f.max_depth << "min_samples" << f.min_samples << "}";
}

ForestOptions read_forest_options(const cv::FileNode& n) {
  return ForestOptions{static_cast<int>(n["trees"]), static_cast<int>(n["max_depth"]),
                       static_cast<int>(n["min_samples"])};
}

void write_forest(cv::FileStorage& fs, const std::string& name, const cv::ml::RTrees& forest) {
  fs << name << "{";
  forest.write(fs);
  fs << "}";
}

// A forest's trees as OpenCV stores them (each tree's nodes in preorder with their depth;
// a node with splits is followed by its two subtrees), checked before OpenCV reads them:
// a tree cut before its leaves, a split on a variable the model does not have, or a depth
// beyond what training allows once made loading hang or predict read out of bounds.
void check_forest_structure(const cv::FileNode& forest, const std::string& file, const std::string& name) {
  constexpr int kMaxTreeDepth = 64;
  constexpr int64_t kMaxNodes = int64_t{1} << 26;
  const int var_all = static_cast<int>(forest["var_all"]);
  NSG_CHECK(var_all > 0 && var_all < (1 << 20), ParseError, file, name + "/var_all", "a variable count");
  const cv::FileNode trees = forest["trees"];
  NSG_CHECK(trees.isSeq() && trees.size() > 0, ParseError, file, name + "/trees", "a list of trees");
  // Iterators, not operator[]: FileNode indexes a sequence by walking it, so indexing
  // every node of a long tree is quadratic (a 64 KiB file of nodes took seconds).
  int64_t total = 0;
  size_t t = 0;
  for (auto tree = trees.begin(); tree != trees.end(); ++tree, ++t) {
    const std::string at = name + "/trees/" + std::to_string(t) + "/nodes";
    const cv::FileNode nodes = (*tree)["nodes"];
    NSG_CHECK(nodes.isSeq() && nodes.size() > 0, ParseError, file, at, "a tree's nodes");
    total += static_cast<int64_t>(nodes.size());
    NSG_CHECK(total <= kMaxNodes, ParseError, file, at, "at most 2^26 nodes in all");
    std::vector<int> expected{0};  // depths of the subtrees still to come, next on top
    size_t k = 0;
    for (auto it = nodes.begin(); it != nodes.end(); ++it, ++k) {
      const cv::FileNode node = *it;
      const std::string nat = at + "/" + std::to_string(k);
      NSG_CHECK(!expected.empty(), ParseError, file, nat, "no node after the tree is complete");
      const int want = expected.back();
      expected.pop_back();
      NSG_CHECK(node["depth"].isInt() && static_cast<int>(node["depth"]) == want, ParseError, file, nat + "/depth",
                "depth " + std::to_string(want) + " (nodes in preorder)");
      const cv::FileNode splits = node["splits"];
      if (splits.empty()) continue;  // a leaf
      NSG_CHECK(want < kMaxTreeDepth, ParseError, file, nat, "a tree at most 64 deep");
      size_t s = 0;
      for (auto split = splits.begin(); split != splits.end(); ++split, ++s) {
        const cv::FileNode var = (*split)["var"];
        NSG_CHECK(var.isInt() && static_cast<int>(var) >= 0 && static_cast<int>(var) < var_all, ParseError, file,
                  nat + "/splits/" + std::to_string(s) + "/var",
                  "a variable index below var_all " + std::to_string(var_all));
      }
      expected.push_back(want + 1);  // the right subtree, after the left
      expected.push_back(want + 1);
    }
    NSG_CHECK(expected.empty(), ParseError, file, at, "a complete tree (it ends before its leaves)");
  }
}

cv::Ptr<cv::ml::RTrees> read_forest(const cv::FileStorage& fs, const std::string& name, const std::string& file) {
  NSG_CHECK(!fs[name].empty(), ParseError, file, name, "a trained forest '" + name + "' (the variant needs it)");
  check_forest_structure(fs[name], file, name);
  cv::Ptr<cv::ml::RTrees> rt = cv::ml::RTrees::create();
  rt->read(fs[name]);
  NSG_CHECK(rt->isTrained(), ParseError, file, name, "a trained forest");
  return rt;
}

// The variant's extra options (b2, graph); b1 files carry none of these keys.
void write_variant_options(cv::FileStorage& fs, const ModelOptions& o) {
  if (o.variant == Variant::kB1) return;
  write_forest_options(fs, "anchor_forest", o.anchor);
  write_fields(fs, "anchors", o.anchors, kAnchorFields);
  if (o.variant != Variant::kGraph) return;
  write_forest_options(fs, "connection_forest", o.connection);
  write_fields(fs, "pairs", o.pairs, kPairFields);
  fs << "pair_features"
     << "[";
  for (const auto& n : pair_feature_names()) fs << n;
  fs << "]";
}

void read_variant_options(const cv::FileStorage& fs, ModelOptions& o, const std::string& file) {
  if (o.variant == Variant::kB1) return;
  o.anchor = read_forest_options(fs["anchor_forest"]);
  read_fields(fs["anchors"], o.anchors, kAnchorFields, file, "anchors");
  if (o.variant != Variant::kGraph) return;
  o.connection = read_forest_options(fs["connection_forest"]);
  read_fields(fs["pairs"], o.pairs, kPairFields, file, "pairs");
  std::vector<std::string> names;
  for (const auto& n : fs["pair_features"]) names.push_back(static_cast<std::string>(n));
  NSG_CHECK(names == pair_feature_names(), ParseError, file, "pair_features",
            "the pair feature list of this nsgraph version (retrain the model)");
}

}  // namespace

void LaneModel::save(const std::filesystem::path& path) const {
  const Impl& m = *impl_;
  cv::FileStorage fs(".yml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
  fs << "format" << kFormat << "format_version" << kFormatVersion << "tool_version" << kVersion;
  // A b1 file leaves the variant out: absent means b1, so b1 files stay byte-identical
  // to the files written before the variants existed (and those load as b1).
  if (m.options.variant != Variant::kB1) fs << "variant" << to_string(m.options.variant);
  fs << "modalities" << m.options.modalities.to_string();
  fs << "features"
     << "[";
  for (const auto& n : m.feature_names) fs << n;
  fs << "]";
  fs << "predict_stride_px" << m.options.predict_stride_px;
  // The seed as text: FileStorage numbers are int or double, too narrow for every uint64.
  fs << "sigma_px" << m.options.sigma_px << "seed" << std::to_string(m.options.seed);
  write_forest_options(fs, "centre_forest", m.options.centre);
  write_forest_options(fs, "direction_forest", m.options.direction);
  write_fields(fs, "extraction", m.options.extraction, kExtractionFields);
  write_variant_options(fs, m.options);
  // Numbers in the map (OpenCV's YAML writer mangles strings that look like JSON); the
  // split's name, a plain word, beside it.
  fs << "training_report"
     << "{";
  for (const auto& [k, v] : m.report.items()) {
    if (v.is_number()) fs << k << v.get<double>();
  }
  fs << "}";
  if (m.report.contains("split") && m.report["split"].is_string())
    fs << "training_split" << m.report["split"].get<std::string>();
  write_forest(fs, "centre", *m.centre);
  write_forest(fs, "direction", *m.direction);
  if (m.anchor) write_forest(fs, "anchor", *m.anchor);
  if (m.connection) write_forest(fs, "connection", *m.connection);
  const std::string text = fs.releaseAndGetString();
  const bool gz = path.extension() == ".gz";
  write_file_atomic(path, gz ? gzip_compress(text) : text);
}

LaneModel LaneModel::load(const std::filesystem::path& path) { return load(path, kMaxModelTextBytes); }

LaneModel LaneModel::load(const std::filesystem::path& path, uint64_t max_text_bytes) {
  const std::string file = path.string();
  std::string text = read_maybe_gzip(path, std::min(max_text_bytes, kMaxModelTextBytes));
  // OpenCV 4.6's YAML reader loops without end on a document marker run into text
  // ("---Jformat: …", found by fuzz_model); our writer puts "---" on a line of its own.
  const size_t marker = text.find("---");
  NSG_CHECK(marker == std::string::npos || marker + 3 == text.size() ||
                std::string_view(" \t\r\n").find(text[marker + 3]) != std::string_view::npos,
            ParseError, file, "document marker", "'---' on a line of its own (as nsgraph writes models)");
  LaneModel model;
  Impl& m = *model.impl_;
  try {
    cv::FileStorage fs(text, cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
    NSG_CHECK(fs.isOpened() && static_cast<std::string>(fs["format"]) == kFormat, ParseError, file, "format",
              std::string("an nsgraph model (format: ") + kFormat + ")");
    NSG_CHECK(static_cast<int>(fs["format_version"]) == kFormatVersion, ParseError, file, "format_version",
              "version " + std::to_string(kFormatVersion));
    // Files from before the variants hold today's b1.
    m.options.variant =
        fs["variant"].empty() ? Variant::kB1 : parse_variant(static_cast<std::string>(fs["variant"]), "variant");
    m.options.modalities = Modalities::parse(static_cast<std::string>(fs["modalities"]));
    for (const auto& n : fs["features"]) m.feature_names.push_back(static_cast<std::string>(n));
    NSG_CHECK(m.feature_names == feature_names(m.options.modalities), ParseError, file, "features",
              "the feature list of this nsgraph version for modalities " + m.options.modalities.to_string() +
                  " (retrain the model)");
    m.options.sigma_px = static_cast<double>(fs["sigma_px"]);
    m.options.predict_stride_px = static_cast<int>(fs["predict_stride_px"]);
    const std::string seed = static_cast<std::string>(fs["seed"]);
    const auto [end, ec] = std::from_chars(seed.data(), seed.data() + seed.size(), m.options.seed);
    NSG_CHECK(ec == std::errc() && end == seed.data() + seed.size() && !seed.empty(), ParseError, file, "seed",
              "an unsigned integer as text");
    m.options.centre = read_forest_options(fs["centre_forest"]);
    m.options.direction = read_forest_options(fs["direction_forest"]);
    read_fields(fs["extraction"], m.options.extraction, kExtractionFields, file, "extraction");
    read_variant_options(fs, m.options, file);
    m.report = nlohmann::json::object();
    for (const auto& n : fs["training_report"]) m.report[n.name()] = static_cast<double>(n);
    if (fs["training_split"].isString()) m.report["split"] = static_cast<std::string>(fs["training_split"]);
    m.centre = read_forest(fs, "centre", file);
    m.direction = read_forest(fs, "direction", file);
    if (m.options.variant != Variant::kB1) m.anchor = read_forest(fs, "anchor", file);
    if (m.options.variant == Variant::kGraph) m.connection = read_forest(fs, "connection", file);
  } catch (const Error&) {
    throw;
  } catch (const cv::Exception& ex) {
    throw ParseError(file, "model", std::string("a readable OpenCV FileStorage (") + ex.what() + ")");
  } catch (const std::exception& ex) {
    // OpenCV's YAML reader also lets standard exceptions through on malformed text
    // (std::length_error from a string it sizes from the input: found by fuzz_model).
    throw ParseError(file, "model", std::string("a readable OpenCV FileStorage (") + ex.what() + ")");
  }
  m.options.validate();
  return model;
}

}  // namespace nsg::model

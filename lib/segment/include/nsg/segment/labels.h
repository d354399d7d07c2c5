#pragma once
// The labels file of a semantic-segmentation model (schemas/v1/segment-labels.schema.json):
// how to feed the model (`input`) and which of our classes (samples/semantic-classes.json)
// each output channel means (`classes`: channel index → class name or "void"; unmapped
// channels are void). The same format maps nuScenes-lidarseg's 32 labels to our classes
// (samples/semantic-labels/nuscenes-lidarseg.json), where `input` is left out.
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nsg/core/semantic_classes.h"

namespace nsg::segment {

inline constexpr uint8_t kVoid = kSemanticVoid;

// Our class names by id (nsg/core/semantic_classes.h; a test keeps them equal to
// samples/semantic-classes.json).
const std::vector<std::string>& class_names();

// How an image becomes the model's input: resized (bilinear) to width × height, channel
// order RGB (else BGR), each value v → (v · scale − mean[c]) / std[c], NCHW float32.
struct ModelInput {
  int width = 0, height = 0;
  bool rgb = true;
  double scale = 1.0 / 255.0;
  std::array<double, 3> mean{0.0, 0.0, 0.0};
  std::array<double, 3> std{1.0, 1.0, 1.0};
};

struct SegmentLabels {
  std::string file;  // where it came from, for messages
  std::optional<ModelInput> input;
  std::vector<uint8_t> class_of_channel;  // our class id per channel up to the highest named one
  // Our class id of a channel (kVoid beyond the named ones).
  uint8_t class_of(size_t channel) const {
    return channel < class_of_channel.size() ? class_of_channel[channel] : kVoid;
  }
  // The highest channel the file names (−1 if none).
  int max_channel() const { return static_cast<int>(class_of_channel.size()) - 1; }
  // The lookup by uint8 label (lidarseg): 256 entries, kVoid where unnamed.
  std::array<uint8_t, 256> table() const;
};

// Checks `doc` against the published schema (schemas_dir as validate::find_schemas_dir)
// and then the meaning: every class name one of ours or "void". Throws ParseError naming
// `file_label` and the JSON pointer of the first problem (exit 2).
SegmentLabels labels_from_json(const nlohmann::json& doc, const std::string& file_label,
                               const std::filesystem::path& schemas_dir = {});
// Reads and checks a labels file (IoError / ParseError naming it).
SegmentLabels load_labels(const std::filesystem::path& file, const std::filesystem::path& schemas_dir = {});

// nuScenes-lidarseg → our classes, the built-in copy of
// samples/semantic-labels/nuscenes-lidarseg.json (a test keeps them equal), so generate
// needs no file at run time.
const SegmentLabels& builtin_lidarseg_labels();

}  // namespace nsg::segment

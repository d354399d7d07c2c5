#pragma once
// The options of `nsgraph train`, each declared once (nsg/core/options.h): the reference
// model's options (forests, sampling, anchors, pairs, graph extraction) and the split to
// train on. Reading a config file, --set, the command's flags, range errors naming the key
// and its source, --list-options and schemas/v1/train-config.schema.json come from these
// declarations; the validate() of each options struct runs the same declarations.
#include <filesystem>
#include <string>
#include <vector>

#include "nsg/core/options.h"
#include "nsg/model/model.h"

namespace nsg::model {

struct TrainConfig {
  std::string split = "train";
  ModelOptions model = [] {
    ModelOptions m;
    m.variant = Variant::kGraph;  // the full model is what `train` builds unless told otherwise
    return m;
  }();
};

const options::Table<ModelOptions>& model_option_table();
const options::Table<TrainConfig>& train_option_table();
options::OrderedJson train_config_schema();

// options::resolve_config's precedence: the defaults, the file ("" = none), each --set
// "key=value", then the flags (--variant for "variant"). Errors name the key and the file,
// --set or flag it came from.
TrainConfig resolve_train_config(const std::filesystem::path& file, const std::vector<std::string>& settings,
                                 const std::vector<options::FlagValue>& flags = {},
                                 options::Origins* origins = nullptr);

}  // namespace nsg::model

#include "nsg/pipeline/ladder.h"

#include <algorithm>
#include <set>

#include "nsg/core/error.h"
#include "nsg/core/rng.h"
#include "nsg/core/strings.h"
#include "nsg/nuscenes/database.h"
#include "nsg/tiling/regions.h"

namespace nsg::pipeline {

using nlohmann::json;
using nlohmann::ordered_json;
using options::Spec;

bool LadderOptions::covers(const std::string& split) const {
  return enabled() && std::find(splits.begin(), splits.end(), split) != splits.end();
}

std::vector<int> LadderOptions::built_rungs() const {
  std::vector<int> out;
  for (int r : rungs)
    if (r != kRungAll) out.push_back(r);
  return out;
}

std::string rung_name(int rung) { return rung == kRungAll ? "all" : std::to_string(rung); }

std::string rung_key(const std::string& key, int rung) { return key + "-r" + rung_name(rung); }

std::string rung_shard_name(const std::string& split_shard_name, const std::string& split, int rung) {
  // "<split>-NNNNNN" → "<split>-r<k>-NNNNNN": the number stays, so a rung shard holds the
  // rung tiles of exactly the split shard of that number.
  if (split_shard_name.compare(0, split.size() + 1, split + "-") != 0)
    throw InternalError("", split_shard_name, "a shard name <split>-NNNNNN of split " + split);
  return split + "-r" + rung_name(rung) + split_shard_name.substr(split.size());
}

namespace {

constexpr int kMaxRung = 100000;  // more scenes than any location of the real release has

std::vector<int> read_rungs(const json& v, const Spec& s) {
  if (!v.is_array()) options::reject(v, s);
  std::vector<int> out;
  for (size_t i = 0; i < v.size(); ++i) {
    const json& x = v[i];
    const std::string here = s.key + "[" + std::to_string(i) + "]";
    int rung = 0;
    if (x.is_string() && x.get_ref<const std::string&>() == "all") {
      rung = kRungAll;
    } else if (x.is_number_integer() && x.get<int64_t>() >= 1 && x.get<int64_t>() <= kMaxRung) {
      rung = static_cast<int>(x.get<int64_t>());
    } else {
      throw ConfigError("", here, strprintf("a scene count in [1, %d] or \"all\"", kMaxRung));
    }
    if (!out.empty() && rung <= out.back())
      throw ConfigError("", here, "rungs in ascending order, each once, \"all\" last");
    out.push_back(rung);
  }
  return out;
}

std::vector<std::string> read_splits(const json& v, const Spec& s) {
  if (!v.is_array() || v.empty()) options::reject(v, s);
  std::vector<std::string> out;
  for (size_t i = 0; i < v.size(); ++i) {
    const std::string split = options::read_string(v[i], s);
    if (tiling::split_index(split) < 0 || std::find(out.begin(), out.end(), split) != out.end())
      throw ConfigError("", s.key + "[" + std::to_string(i) + "]", "a split name (train, val, test), each once");
    out.push_back(split);
  }
  return out;
}

}  // namespace

const options::Table<LadderOptions>& ladder_option_table() {
  static const options::Table<LadderOptions> table = [] {
    options::Table<LadderOptions> t;
    t.shape(
         "ladder.rungs", "an array of scene counts ≥ 1 in ascending order, optionally ending with \"all\"",
         {{"type", "array"},
          {"items", {{"oneOf", {{{"type", "integer"}, {"minimum", 1}, {"maximum", kMaxRung}}, {{"const", "all"}}}}}}},
         [](const LadderOptions& o) {
           ordered_json out = ordered_json::array();
           for (int r : o.rungs) r == kRungAll ? out.push_back("all") : out.push_back(r);
           return out;
         },
         [](LadderOptions& o, const json& v, const Spec& s) { o.rungs = read_rungs(v, s); })
        .help(
            "Observation ladder: for each tile of ladder.splits, one tile per rung k rebuilt from the first k scenes "
            "that saw it (\"all\" = the split's own tile); [] = no ladder (--ladder sets [1, 2, 4, \"all\"])");
    t.choice("ladder.order", &LadderOptions::order, {{"time", LadderOrder::kTime}, {"seeded", LadderOrder::kSeeded}})
        .help("Which of a tile's scenes come first: by capture time, or a shuffle seeded by the seed and tile key");
    t.shape(
         "ladder.splits", "a non-empty array of split names",
         {{"type", "array"}, {"minItems", 1}, {"items", {{"enum", {"train", "val", "test"}}}}},
         [](const LadderOptions& o) { return ordered_json(o.splits); },
         [](LadderOptions& o, const json& v, const Spec& s) { o.splits = read_splits(v, s); })
        .help("Splits whose tiles get rungs");
    return t;
  }();
  return table;
}

std::vector<nuscenes::Index> ladder_order(const nuscenes::Database& db, std::vector<nuscenes::Index> scenes,
                                          LadderOrder order, uint64_t seed, const std::string& tile_key) {
  std::sort(scenes.begin(), scenes.end());
  if (order == LadderOrder::kSeeded) {
    Rng rng(seed, hash_string(tile_key.data(), tile_key.size()));
    rng.shuffle(scenes);
    return scenes;
  }
  const auto captured_us = [&](nuscenes::Index s) {
    const nuscenes::Index first = db.scene[s].first_sample;
    return first == nuscenes::kNoIndex ? std::numeric_limits<int64_t>::max() : db.sample[first].timestamp_us;
  };
  std::stable_sort(scenes.begin(), scenes.end(),
                   [&](nuscenes::Index a, nuscenes::Index b) { return captured_us(a) < captured_us(b); });
  return scenes;
}

std::vector<nuscenes::Index> rung_scenes(const std::vector<nuscenes::Index>& ordered, int rung) {
  const size_t n = std::min(ordered.size(), static_cast<size_t>(rung));
  std::vector<nuscenes::Index> out(ordered.begin(), ordered.begin() + static_cast<std::ptrdiff_t>(n));
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace nsg::pipeline

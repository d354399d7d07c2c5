#pragma once
// The observation ladder (docs/generating.md, "Observation ladder"): the tiles of chosen
// splits rebuilt from the first k scenes that saw them, one tile per rung, so a model can be
// scored after 1, 2, 4 … drives while the ground truth stays the same. Declared here once:
// the `ladder.*` config keys, the rung names, keys and shard names, and the choice of each
// tile's scenes.
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "nsg/core/options.h"
#include "nsg/nuscenes/token.h"

namespace nsg::nuscenes {
class Database;
}

namespace nsg::pipeline {

// The rung of every scene that saw a tile ("all" in a config and in the manifest).
inline constexpr int kRungAll = std::numeric_limits<int>::max();

enum class LadderOrder {
  kTime,    // a tile's scenes by capture time (their first sample's timestamp)
  kSeeded,  // a seeded shuffle per tile (config seed and tile key)
};

struct LadderOptions {
  std::vector<int> rungs;                   // ascending scene counts, kRungAll last; [] = no ladder
  LadderOrder order = LadderOrder::kTime;   // which of a tile's scenes come first
  std::vector<std::string> splits{"test"};  // the splits whose tiles get rungs
  bool enabled() const { return !rungs.empty(); }
  bool covers(const std::string& split) const;
  // The rungs written as tiles of their own (every rung but "all": the split's own tiles
  // are the "all" rung).
  std::vector<int> built_rungs() const;
};

const options::Table<LadderOptions>& ladder_option_table();
// What `--ladder` sets ladder.rungs to.
inline constexpr const char* kDefaultLadderRungs = R"([1, 2, 4, "all"])";

// "1", "2", … or "all".
std::string rung_name(int rung);
// A rung tile's key: the split tile's key and "-r<k>" ("boston-seaport-test-000012-r2").
std::string rung_key(const std::string& key, int rung);
// A rung shard's name: "<split>-r<k>-NNNNNN" for the split shard "<split>-NNNNNN".
std::string rung_shard_name(const std::string& split_shard_name, const std::string& split, int rung);

// The scenes of a tile in ladder order: by capture time (the scene's first sample; ties and
// scenes without samples by table order) or in a shuffle seeded by `seed` and `tile_key`
// (the project's own RNG, the same on every platform).
std::vector<nuscenes::Index> ladder_order(const nuscenes::Database& db, std::vector<nuscenes::Index> scenes,
                                          LadderOrder order, uint64_t seed, const std::string& tile_key);
// The first min(rung, n) of `ordered`, back in table order (the order the accumulation reads).
std::vector<nuscenes::Index> rung_scenes(const std::vector<nuscenes::Index>& ordered, int rung);

}  // namespace nsg::pipeline

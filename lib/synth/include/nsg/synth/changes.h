#pragma once
// Map changes of a synthetic world (config `changes`, docs/synthetic-release.md "Map changes"):
// the world as built (the prior) and the same world after seeded atomic edits (the current),
// for the scenes captured from `changes.from_day` on. Every record of the prior map keeps its
// token in the current one unless an edit removed it; an edit's new records draw their tokens
// after every prior record's, so the prior map is byte-identical to the world without changes.
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "nsg/synth/config.h"
#include "nsg/synth/world.h"

namespace nsg::synth {

// One atomic edit: what it is, the map tokens it takes out of the current map and the ones it
// puts in, and a point of it (map frame, m).
struct MapEdit {
  std::string kind;  // one of kMapEditKinds
  std::vector<std::string> removed;
  std::vector<std::string> added;
  std::vector<std::string> retyped;  // records kept with another type (a divider and its two lanes)
  std::array<double, 2> at_m{};
};

// The names of MapEdit::kind, in the order the edits are drawn.
inline constexpr std::array<const char*, 5> kMapEditKinds = {"lane_closed", "turn_removed", "turn_added",
                                                             "divider_retyped", "crossing_added"};

struct ChangedWorld {
  World prior;    // build_world(config, seed), exactly
  World current;  // the prior with `edits` applied: lanes, map JSON, ground paint, barriers
  std::vector<MapEdit> edits;
};

// Edits are kept ≥ this far apart (their points), so each stays atomic in a tile's view.
inline constexpr double kMinEditSpacingM = 40.0;

// changes.json of a release (schemas/v1/synth-changes.schema.json): the one model of it.
struct MapChanges {
  std::string location;
  int from_day = 1;
  std::string date;         // YYYY-MM-DD: log.date_captured of the first changed scene
  std::string prior_map;    // "maps/prior/expansion/<location>.json", relative to the release
  std::string current_map;  // "maps/expansion/<location>.json"
  std::vector<MapEdit> edits;
};

// What the format allows (the reader's limits): a release's changes are few.
inline constexpr int64_t kMaxMapChangesBytes = int64_t{4} << 20;
inline constexpr size_t kMaxMapEdits = 500;
inline constexpr size_t kMaxTokensPerEdit = 64;

// The one writer (`nsgraph synth`) and the one reader. The reader bounds the size before
// reading, parses strictly and checks every field against the schema's rules; ParseError
// naming the file, the JSON pointer and what was expected.
std::string map_changes_text(const MapChanges& changes);
MapChanges read_map_changes(const std::filesystem::path& file);

// Builds the prior world and applies config.changes to a copy (deterministic in the seed).
// ConfigError naming the key when the world has fewer places for an edit kind than asked.
ChangedWorld build_changed_world(const SynthConfig& config, uint64_t seed);

}  // namespace nsg::synth

#pragma once
// Map defects the devkit loads without complaint (docs/nuscenes-input.md "Map expansion v1.3"): null
// tokens, "" links, lines without nodes, empty holes, self-intersecting rings. They are
// collected while reading and reported in MapExpansion::issues(), grouped per (check,
// layer, key): queenstown's 676 null road_block.polygon_tokens make one issue, not 676.
#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "nsg/core/issues.h"
#include "nsg/nuscenes/map_expansion.h"

namespace nsg::nuscenes::map_detail {

class MapDefectLog {
 public:
  explicit MapDefectLog(std::string file) : file_(std::move(file)) {}

  // One occurrence. `record` names the record: "'<token>'", or "#<index>" when its token is
  // null or empty. `what` says what was found and what nsgraph did (same text per group).
  void add(Severity severity, std::string_view check, std::string_view layer, std::string_view key, std::string record,
           std::string_view what);

  // One issue per group, in order of first occurrence. Subject: "<file>: <layer> <first
  // record>"; message: "key \"<key>\" <what>: <count> record(s) (<first few>)".
  Issues issues() const;

 private:
  struct Group {
    Severity severity;
    std::string check, layer, key, what;
    std::vector<std::string> examples;  // the first few records
    size_t count = 0;
  };
  std::string file_;
  std::vector<Group> groups_;  // a handful per map: a linear search is enough
};

// "'<token>'" or "#<index>" for a record whose token is null/empty.
std::string record_label(std::string_view token, size_t index);

// Checks run on the loaded records: lines with zero nodes, holes with no nodes and
// self-intersecting exterior rings (warnings; the devkit loads all of them).
void check_geometry(const MapExpansion& map, MapDefectLog& log);

// True if the closed ring through `points` (not repeated at the end) has two non-adjacent
// edges that cross or touch. Zero-length edges (a node repeated in a row) are ignored.
// Sort-and-sweep over x: near-linear on map polygons, quadratic only in contrived cases.
bool ring_self_intersects(const std::vector<std::array<double, 2>>& points);

}  // namespace nsg::nuscenes::map_detail

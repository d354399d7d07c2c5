#pragma once
// The map expansion reader's builder, internal to the nuscenes module: MapExpansion's friend
// that fills it in two passes —
// map_parse.cpp: one simdjson on-demand pass over the file into typed records;
// map_resolve.cpp: the token indexes, the resolved references and the load order.
#include <array>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "map_defects.h"
#include "map_json.h"
#include "nsg/nuscenes/map_expansion.h"

namespace nsg::nuscenes {

// Fills a MapExpansion (friend): parse, then index and resolve.
class MapExpansionBuilder {
 public:
  static MapExpansion load(const std::filesystem::path& path);

 private:
  MapExpansionBuilder(MapExpansion& map, const std::filesystem::path& path) : m_(map), defects_(path.string()) {
    c_.file = path.string();
    c_.defects = &defects_;
  }
  void parse(const std::filesystem::path& path);
  void parse_top_level(map_detail::od::object& top);
  template <class R, size_t N>
  void read_layer(map_detail::od::value& v, std::string_view layer, const std::array<map_detail::Field<R>, N>& spec,
                  std::vector<R>& out);
  void read_arclines(map_detail::od::value& v);
  void read_connectivity(map_detail::od::value& v);
  void check_version(const std::string& version) const;
  [[noreturn]] void fail_truncated(std::string_view json) const;

  void index_layers();
  template <class R>
  void index_layer(MapLayer layer, const std::vector<R>& records);
  MapIndex resolve(MapLayer target, std::string_view token, MapLayer from, const std::string& from_token,
                   std::string_view field) const;
  void resolve_references();
  void resolve_drivable_areas();

  MapExpansion& m_;
  map_detail::MapDefectLog defects_;
  map_detail::Ctx c_;
};

}  // namespace nsg::nuscenes

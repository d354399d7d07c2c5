#pragma once
// GeoJSON export of a lane graph for QGIS (docs/dataset-format.md): WGS 84 lon/lat through the
// devkit's projection of the location, one LineString feature per directed edge (first
// coordinate = source) with its lane token and attributes (kind "successor"), then one per
// lane change (kind "lane_change") and one Point per fork or join (kind "junction").
#include <ostream>
#include <string>
#include <string_view>

#include "nsg/graph/lane_graph.h"

namespace nsg::graph {

void write_geojson(const LaneGraph& graph, std::string_view location, std::ostream& out);
// Writes atomically (temp + rename).
void write_geojson_file(const LaneGraph& graph, std::string_view location, const std::string& path);

}  // namespace nsg::graph

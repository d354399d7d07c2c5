// nsgraph.Dataset's engine: io::SplitIndex for random access, io's GeoTIFF and graph
// decoders. Reading and decoding run without the GIL so DataLoader workers (and threads)
// proceed in parallel; only the wrapping into numpy arrays and dicts holds it.
#include <algorithm>
#include <optional>
#include <utility>

#include "bindings.h"
#include "convert.h"
#include "nsg/core/error.h"
#include "nsg/core/semantic_classes.h"
#include "nsg/core/strings.h"
#include "nsg/graph/lane_attributes.h"
#include "nsg/graph/map_changes.h"
#include "nsg/io/tile_graph.h"
#include "nsg/io/tile_members.h"
#include "nsg/io/tile_index.h"

namespace nsg::py_bind {
namespace {

// The raster layers a tile holds (io/tile_members.h).
const std::vector<std::string>& raster_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const io::TileMember* m : io::raster_members()) out.push_back(m->name);
    return out;
  }();
  return names;
}

// nsgraph.TILE_MEMBERS: every member of a tile as io declares it, for the Python side.
py::tuple tile_members_to_py() {
  py::list out;
  for (const io::TileMember& t : io::tile_members()) {
    py::dict d;
    d["name"] = t.name;
    d["file"] = t.file;
    d["raster"] = t.raster;
    d["dtype"] = t.raster ? py::object(py::str(io::dtype_name(t.dtype))) : py::object(py::none());
    d["bands"] = t.bands;
    d["unit"] = t.unit;
    d["nodata"] = t.nodata ? py::object(py::float_(*t.nodata)) : py::object(py::none());
    d["coverage_bit"] = t.coverage_bit;
    d["description"] = t.description;
    out.append(d);
  }
  return py::tuple(out);
}

// Bands and sample type of a layer (docs/dataset-format.md); its size is the manifest's size_px.
io::RasterHeader expected_raster(const std::string& layer, int size_px) {
  const bool rgb = layer == "rgb", vehicle = layer == "vehicle";
  return {size_px, size_px, rgb ? 3 : 1, vehicle ? io::SampleType::kFloat32 : io::SampleType::kUInt8};
}

// Checked against the header before decoding: a small hostile file claiming a huge image
// (or a deflate bomb) allocates nothing, and a layer of the wrong shape or type is named.
io::Raster decode_layer(const io::DatasetTile& tile, const std::string& layer, int size_px) {
  const std::string suffix = layer + ".tif", name = tile.key + "." + suffix;
  const auto it = tile.files.find(suffix);
  if (it == tile.files.end()) return tile.raster(suffix);  // its "missing" error
  io::check_raster_header(io::read_geotiff_header(it->second, name), expected_raster(layer, size_px), name,
                          "shard " + tile.shard);
  return tile.raster(suffix);
}

// One tile decoded in C++ (no Python objects: built without the GIL).
struct DecodedTile {
  std::string key, shard;
  std::vector<std::pair<std::string, io::Raster>> rasters;
  graph::TileGraph graph;
  bool has_graph = false;
  std::optional<graph::TileGraph> prior;  // a map-update tile's prior graph
  nlohmann::json meta;
};

DecodedTile decode(const io::SplitIndex& index, size_t i, const std::vector<std::string>& layers, bool graph,
                   bool meta) {
  std::vector<std::string> suffixes;
  for (const std::string& l : layers) suffixes.push_back(l + ".tif");
  if (graph) suffixes.push_back("graph.json");
  if (meta) suffixes.push_back("meta.json");
  const io::DatasetTile tile = index.read(i, suffixes);
  DecodedTile out{tile.key, tile.shard, {}, {}, graph, {}, {}};
  for (const std::string& l : layers) out.rasters.emplace_back(l, decode_layer(tile, l, index.size_px()));
  if (graph) {
    const nlohmann::json doc = tile.json("graph.json");
    out.graph = io::tile_graph_from_json(doc, tile.key + ".graph.json");
    out.prior = io::tile_prior_graph_from_json(doc, tile.key + ".graph.json");
  }
  // Through the checked reader and back: Python sees exactly the fields the format defines.
  if (meta) out.meta = nlohmann::json(io::tile_meta_to_json(tile.meta()));
  return out;
}

// The tile's graph with its attributes (docs/dataset-format.md "Graph attributes"): junction
// and turn as codes into nsgraph.JUNCTIONS and nsgraph.TURNS.
py::dict graph_to_py(const graph::TileGraph& g) {
  std::vector<std::array<double, 2>> px, m;
  std::vector<std::array<int64_t, 2>> edges, lane_changes;
  std::vector<int64_t> ids, junction, turn, change;
  std::vector<bool> connector, in_intersection;
  py::list tokens, change_tokens;
  for (const graph::TileNode& n : g.nodes) {
    px.push_back({n.u_px, n.v_px});
    m.push_back({n.x_m, n.y_m});
    ids.push_back(n.id);
    junction.push_back(static_cast<int64_t>(n.junction));
  }
  for (const graph::TileEdge& e : g.edges) {
    edges.push_back({e.source, e.target});
    tokens.append(py::str(e.lane_token));
    connector.push_back(e.is_connector);
    in_intersection.push_back(e.in_intersection);
    turn.push_back(static_cast<int64_t>(e.turn));
    change.push_back(static_cast<int64_t>(e.change));
  }
  for (const graph::TileLaneChange& c : g.lane_changes) {
    lane_changes.push_back({c.source, c.target});
    change_tokens.append(py::make_tuple(c.from_lane_token, c.to_lane_token));
  }
  py::dict d;
  d["nodes_px"] = pairs_to_numpy(px);
  d["nodes_m"] = pairs_to_numpy(m);
  d["edges"] = pairs_to_numpy(edges);
  d["lane_tokens"] = tokens;
  d["node_ids"] = ints_to_numpy(ids);
  d["junction"] = ints_to_numpy(junction);
  d["connector"] = bools_to_numpy(connector);
  d["in_intersection"] = bools_to_numpy(in_intersection);
  d["turn"] = ints_to_numpy(turn);
  d["change"] = ints_to_numpy(change);
  d["lane_changes"] = pairs_to_numpy(lane_changes);
  d["lane_change_tokens"] = change_tokens;
  return d;
}

py::dict to_py(DecodedTile&& t) {
  py::dict d;
  d["key"] = t.key;
  d["shard"] = t.shard;
  for (auto& [name, raster] : t.rasters) d[py::str(name)] = raster_to_numpy(std::move(raster));
  if (t.has_graph) d["graph"] = graph_to_py(t.graph);
  if (t.prior) d["prior_graph"] = graph_to_py(*t.prior);
  if (!t.meta.is_null()) d["meta"] = json_to_py(t.meta);
  return d;
}

// The semantic layer's classes in id order: [{"id", "name", "color"}] (nsg/core/semantic_classes.h).
py::list semantic_classes_to_py() {
  py::list out;
  for (const SemanticClassInfo& c : kSemanticClasses) {
    py::dict d;
    d["id"] = static_cast<int>(c.id);
    d["name"] = std::string(c.name);
    d["color"] = py::make_tuple(c.color[0], c.color[1], c.color[2]);
    out.append(d);
  }
  return out;
}

}  // namespace

void bind_dataset(py::module_& m) {
  m.attr("TILE_MEMBERS") = tile_members_to_py();
  m.attr("SEMANTIC_CLASSES") = semantic_classes_to_py();
  m.attr("SEMANTIC_VOID") = static_cast<int>(kSemanticVoid);
  // The attribute codes of a tile's graph (graph_to_py), by their graph.json names.
  m.attr("MAP_CHANGES") = py::make_tuple(
      "", graph::map_change_name(graph::MapChange::kUnchanged), graph::map_change_name(graph::MapChange::kAdded),
      graph::map_change_name(graph::MapChange::kRemoved), graph::map_change_name(graph::MapChange::kMoved),
      graph::map_change_name(graph::MapChange::kRetyped));
  m.attr("TURNS") = py::make_tuple(graph::turn_name(graph::Turn::kStraight), graph::turn_name(graph::Turn::kLeft),
                                   graph::turn_name(graph::Turn::kRight), graph::turn_name(graph::Turn::kUTurn));
  m.attr("JUNCTIONS") =
      py::make_tuple(graph::junction_name(graph::Junction::kNone), graph::junction_name(graph::Junction::kSplit),
                     graph::junction_name(graph::Junction::kMerge), graph::junction_name(graph::Junction::kBoth));
  m.def(
      "dataset_rungs", [](const std::string& root) { return io::Dataset::open(root).rungs(); }, py::arg("root"),
      "The observation ladder's built rungs of the dataset at root (io::Dataset::rungs).");
  py::class_<io::SplitIndex>(m, "SplitIndex",
                             "Random access to the tiles of one split (tar shards indexed once per process).")
      .def(py::init([](const std::string& root, const std::string& split) {
             py::gil_scoped_release release;
             return std::make_unique<io::SplitIndex>(root, split);
           }),
           py::arg("root"), py::arg("split"))
      .def("__len__", &io::SplitIndex::size)
      .def("key", &io::SplitIndex::key, py::arg("i"))
      .def("shard_name", &io::SplitIndex::shard_name, py::arg("i"))
      .def("suffixes", &io::SplitIndex::suffixes, py::arg("i"))
      .def_property_readonly("tar_layout", &io::SplitIndex::tar_layout)
      .def(
          "read",
          [](const io::SplitIndex& index, size_t i, const std::vector<std::string>& layers, bool graph, bool meta) {
            for (const std::string& l : layers)
              NSG_CHECK(std::find(raster_names().begin(), raster_names().end(), l) != raster_names().end(), ConfigError,
                        "", "layer '" + l + "'", "one of " + join(raster_names(), ", "));
            DecodedTile t;
            {
              py::gil_scoped_release release;
              t = decode(index, i, layers, graph, meta);
            }
            return to_py(std::move(t));
          },
          py::arg("i"), py::arg("layers"), py::arg("graph") = true, py::arg("meta") = true,
          "Tile i decoded: {key, shard, <layer>: ndarray, graph: {...}, meta: {...}}.")
      .def(
          "read_member",
          [](const io::SplitIndex& index, size_t i, const std::string& suffix) {
            io::DatasetTile t;
            {
              py::gil_scoped_release release;
              t = index.read(i, {suffix});
            }
            const std::vector<uint8_t>& b = t.files.at(suffix);
            return py::bytes(reinterpret_cast<const char*>(b.data()), b.size());
          },
          py::arg("i"), py::arg("suffix"), "The raw bytes of one member (\"lidar.tif\", \"graph.json\", …).");
}

}  // namespace nsg::py_bind

#include "nsg/model/copy_prior.h"

#include "nsg/core/error.h"
#include "nsg/metrics/io.h"

namespace nsg::model {

metrics::GraphSet copy_prior_dataset(const io::Dataset& dataset, const std::string& split) {
  metrics::GraphSet out;
  dataset.for_each_tile(split, [&](const io::DatasetTile& tile) {
    const std::string file = tile.key + ".graph.json";
    const std::optional<graph::TileGraph> prior = tile.prior_graph();
    NSG_CHECK(prior.has_value(), DataError, file, "/prior",
              "a prior graph (--model prior copies a map-update dataset's prior map: generate with splits.preset "
              "map-update)");
    out[tile.key] = metrics::graph_of_tile(*prior);
    return true;
  });
  return out;
}

}  // namespace nsg::model

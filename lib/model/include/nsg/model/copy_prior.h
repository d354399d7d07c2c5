#pragma once
// The copy-the-prior baseline of a map-update dataset (generate's splits.preset map-update,
// docs/generating.md "Map update"): each tile's prior graph submitted as its prediction. It is
// the floor a map-update method must beat: perfect wherever the map did not change, blind
// to every change.
#include <string>

#include "nsg/io/dataset.h"
#include "nsg/metrics/graph.h"

namespace nsg::model {

// `predict --model prior`: every tile of `split`'s prior graph (graph.json "prior") as a
// submission graph. DataError naming the tile when one has no prior graph (not a map-update
// dataset).
metrics::GraphSet copy_prior_dataset(const io::Dataset& dataset, const std::string& split);

}  // namespace nsg::model

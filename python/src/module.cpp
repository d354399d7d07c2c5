// _nsgraph: the C++ side of the nsgraph Python package (python/nsgraph/*.py hold the
// user-facing API). Thin: each function converts arguments, calls the library, converts
// results.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "convert.h"
#include "nsg/core/version.h"

PYBIND11_MODULE(_nsgraph, m) {
  m.doc() = "C++ core of the nsgraph package (NuScenesGraph toolkit)";
  nsg::py_bind::register_error_translator();
  nsg::py_bind::bind_dataset(m);
  nsg::py_bind::bind_metrics(m);
  nsg::py_bind::bind_graph(m);
  nsg::py_bind::bind_net(m);
  nsg::py_bind::bind_frames(m);
  m.attr("__version__") = nsg::kVersion;
}

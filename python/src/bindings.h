#pragma once
// The parts of the _nsgraph extension, one per library area (module.cpp calls them).
#include <pybind11/pybind11.h>

namespace nsg::py_bind {

void bind_dataset(pybind11::module_& m);
void bind_metrics(pybind11::module_& m);
void bind_graph(pybind11::module_& m);
void bind_net(pybind11::module_& m);
void bind_frames(pybind11::module_& m);

}  // namespace nsg::py_bind

#pragma once
// Conversions between the library's types and Python objects (numpy arrays, dicts), and
// the translation of nsg::Error into the Python exceptions of nsgraph.errors. Nothing
// here computes anything the library computes.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>  // in every part: type casters must agree across files

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nsg/core/issues.h"
#include "nsg/io/raster.h"

namespace nsg::py_bind {

namespace py = pybind11;

using Points = py::array_t<double, py::array::c_style | py::array::forcecast>;
using Pairs = py::array_t<int64_t, py::array::c_style | py::array::forcecast>;

// Issues as a list of {severity, check, subject, message} (hostile bytes quoted printable).
py::list issues_to_py(const Issues& issues);

// nlohmann::json → dict / list / str / int / float / bool / None.
py::object json_to_py(const nlohmann::json& j);
// Parses JSON text; ParseError naming `label` and the byte offset.
nlohmann::json parse_json(const std::string& text, const std::string& label);

// A decoded raster as a numpy array owning its bytes (no copy): uint8 (H, W) or (H, W, 3),
// float32 (H, W).
py::array raster_to_numpy(io::Raster&& raster);
// (rows, 2) arrays from flat row-major data (copies).
py::array_t<double> pairs_to_numpy(const std::vector<std::array<double, 2>>& rows);
py::array_t<int64_t> pairs_to_numpy(const std::vector<std::array<int64_t, 2>>& rows);
py::array_t<double> doubles_to_numpy(const std::vector<double>& values);
py::array_t<int64_t> ints_to_numpy(const std::vector<int64_t>& values);
py::array_t<bool> bools_to_numpy(const std::vector<bool>& values);

// An (N, 2) array argument; ConfigError naming `what` for another shape.
std::vector<std::array<double, 2>> points_arg(const Points& a, const std::string& what);
std::vector<std::array<int64_t, 2>> pairs_arg(const Pairs& a, const std::string& what);

// nsg::Error and its subclasses become nsgraph.errors.<Name> carrying file, record and
// expected as attributes.
void register_error_translator();

}  // namespace nsg::py_bind

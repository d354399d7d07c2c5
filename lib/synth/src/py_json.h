#pragma once
// JSON text exactly as Python's json.dump writes it: `indent=0` (one item per line, no
// indentation; the nuScenes table files) or the compact default (", " and ": "; map
// expansion and detection files). Floats as Python's repr, ints without ".0". Internal.
#include <nlohmann/json.hpp>
#include <string>

namespace nsg::synth {

using PyJson = nlohmann::ordered_json;

// Python's repr(float) for finite values: shortest round-trip digits, fixed notation for
// decimal exponents in [-4, 16), else "1.5e-07" / "1e+16".
std::string python_float_repr(double value);

enum class PyJsonStyle { kIndent0, kCompact };
void append_py_json(std::string& out, const PyJson& value, PyJsonStyle style);
std::string py_json_dump(const PyJson& value, PyJsonStyle style);

}  // namespace nsg::synth

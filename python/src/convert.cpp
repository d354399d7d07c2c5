#include "convert.h"

#include <cstring>
#include <memory>

#include "nsg/core/error.h"
#include "nsg/core/json.h"

namespace nsg::py_bind {

namespace {
py::object json_to_py(const nlohmann::json& j, int depth) {
  // Documents from outside were parsed with parse_json_strict (nesting <= kMaxJsonDepth);
  // the check keeps this recursion bounded whatever the caller passes.
  NSG_CHECK(depth <= kMaxJsonDepth, ParseError, "", "nesting depth " + std::to_string(depth),
            "arrays and objects nested at most " + std::to_string(kMaxJsonDepth) + " deep");
  switch (j.type()) {
    case nlohmann::json::value_t::object: {
      py::dict d;
      for (const auto& [k, v] : j.items()) d[py::str(k)] = json_to_py(v, depth + 1);
      return d;
    }
    case nlohmann::json::value_t::array: {
      py::list l(j.size());
      for (size_t i = 0; i < j.size(); ++i) l[i] = json_to_py(j[i], depth + 1);
      return l;
    }
    case nlohmann::json::value_t::string: return py::str(j.get_ref<const std::string&>());
    case nlohmann::json::value_t::boolean: return py::bool_(j.get<bool>());
    case nlohmann::json::value_t::number_integer: return py::int_(j.get<int64_t>());
    case nlohmann::json::value_t::number_unsigned: return py::int_(j.get<uint64_t>());
    case nlohmann::json::value_t::number_float: return py::float_(j.get<double>());
    default: return py::none();
  }
}
}  // namespace

py::object json_to_py(const nlohmann::json& j) { return json_to_py(j, 0); }

nlohmann::json parse_json(const std::string& text, const std::string& label) { return parse_json_strict(text, label); }

py::array raster_to_numpy(io::Raster&& raster) {
  auto* owned = new std::vector<uint8_t>(std::move(raster.data));
  py::capsule free_when_done(owned, [](void* p) { delete static_cast<std::vector<uint8_t>*>(p); });
  const auto h = static_cast<py::ssize_t>(raster.height), w = static_cast<py::ssize_t>(raster.width);
  if (raster.type == io::SampleType::kFloat32)
    return py::array_t<float>({h, w}, reinterpret_cast<const float*>(owned->data()), free_when_done);
  if (raster.bands == 1) return py::array_t<uint8_t>({h, w}, owned->data(), free_when_done);
  return py::array_t<uint8_t>({h, w, static_cast<py::ssize_t>(raster.bands)}, owned->data(), free_when_done);
}

namespace {
template <typename T>
py::array_t<T> rows_to_numpy(const std::vector<std::array<T, 2>>& rows) {
  py::array_t<T> a({static_cast<py::ssize_t>(rows.size()), py::ssize_t{2}});
  if (!rows.empty()) std::memcpy(a.mutable_data(), rows.data(), rows.size() * sizeof(rows[0]));
  return a;
}
template <typename T>
py::array_t<T> values_to_numpy(const std::vector<T>& values) {
  py::array_t<T> a(static_cast<py::ssize_t>(values.size()));
  if (!values.empty()) std::memcpy(a.mutable_data(), values.data(), values.size() * sizeof(T));
  return a;
}
template <typename T, typename Array>
std::vector<std::array<T, 2>> rows_arg(const Array& a, const std::string& what) {
  // An empty list arrives as shape (0,): accept it as (0, 2).
  if (a.ndim() == 1 && a.shape(0) == 0) return {};
  NSG_CHECK(a.ndim() == 2 && a.shape(1) == 2, ConfigError, "", what,
            "an array of shape (N, 2), got " + std::to_string(a.ndim()) + " dimension(s)" +
                (a.ndim() == 2 ? " with " + std::to_string(a.shape(1)) + " columns" : ""));
  std::vector<std::array<T, 2>> out(static_cast<size_t>(a.shape(0)));
  if (!out.empty()) std::memcpy(out.data(), a.data(), out.size() * sizeof(out[0]));
  return out;
}
}  // namespace

py::array_t<double> pairs_to_numpy(const std::vector<std::array<double, 2>>& rows) { return rows_to_numpy(rows); }
py::array_t<int64_t> pairs_to_numpy(const std::vector<std::array<int64_t, 2>>& rows) { return rows_to_numpy(rows); }
py::array_t<double> doubles_to_numpy(const std::vector<double>& values) { return values_to_numpy(values); }
py::array_t<int64_t> ints_to_numpy(const std::vector<int64_t>& values) { return values_to_numpy(values); }
py::array_t<bool> bools_to_numpy(const std::vector<bool>& values) {
  py::array_t<bool> out(static_cast<py::ssize_t>(values.size()));
  auto w = out.mutable_unchecked<1>();
  for (size_t k = 0; k < values.size(); ++k) w(static_cast<py::ssize_t>(k)) = values[k];
  return out;
}

std::vector<std::array<double, 2>> points_arg(const Points& a, const std::string& what) {
  return rows_arg<double>(a, what);
}
std::vector<std::array<int64_t, 2>> pairs_arg(const Pairs& a, const std::string& what) {
  return rows_arg<int64_t>(a, what);
}

namespace {
void raise(const char* name, const Error& e) {
  // Looked up at raise time: the classes live in Python (nsgraph/errors.py) so they can
  // derive from both nsgraph.Error and ValueError / OSError.
  py::object cls = py::module_::import("nsgraph.errors").attr(name);
  // Messages may quote hostile bytes: escaped, so they always convert to str.
  py::object exc = cls(printable_utf8(e.what()));
  exc.attr("file") = printable_utf8(e.file());
  exc.attr("record") = printable_utf8(e.record());
  exc.attr("expected") = printable_utf8(e.expected());
  PyErr_SetObject(cls.ptr(), exc.ptr());
}
}  // namespace

void register_error_translator() {
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const ParseError& e) {
      raise("ParseError", e);
    } catch (const DataError& e) {
      raise("DataError", e);
    } catch (const IoError& e) {
      raise("IoError", e);
    } catch (const ConfigError& e) {
      raise("ConfigError", e);
    } catch (const Error& e) {
      raise("InternalError", e);
    }
  });
}

py::list issues_to_py(const Issues& issues) {
  py::list out;
  for (const Issue& i : issues.items()) {
    py::dict d;
    d["severity"] = severity_name(i.severity);
    d["check"] = i.check;
    d["subject"] = printable_utf8(i.subject);  // may quote hostile bytes
    d["message"] = printable_utf8(i.message);
    out.append(d);
  }
  return out;
}

}  // namespace nsg::py_bind

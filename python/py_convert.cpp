#include "python/py_convert.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/json_input.hpp"
#include "core/recording.hpp"

namespace hw::python {

py::object ToPython(const nlohmann::json& j) {
  switch (j.type()) {
    case nlohmann::json::value_t::null: return py::none();
    case nlohmann::json::value_t::boolean: return py::bool_(j.get<bool>());
    case nlohmann::json::value_t::number_integer: return py::int_(j.get<std::int64_t>());
    case nlohmann::json::value_t::number_unsigned: return py::int_(j.get<std::uint64_t>());
    case nlohmann::json::value_t::number_float: return py::float_(j.get<double>());
    case nlohmann::json::value_t::string: return py::str(j.get_ref<const std::string&>());
    case nlohmann::json::value_t::array: {
      py::list out;
      for (const auto& e : j) out.append(ToPython(e));
      return std::move(out);
    }
    case nlohmann::json::value_t::object: {
      py::dict out;
      for (const auto& [k, v] : j.items()) out[py::str(k)] = ToPython(v);
      return std::move(out);
    }
    default: throw std::runtime_error("a JSON value of an unsupported type (binary or discarded)");
  }
}

nlohmann::json ToJson(py::handle h) {
  if (h.is_none()) return nullptr;
  if (py::isinstance<py::bool_>(h)) return h.cast<bool>();  // before int: bool is an int in Python
  if (py::isinstance<py::int_>(h)) return h.cast<std::int64_t>();
  if (py::isinstance<py::float_>(h)) return h.cast<double>();
  if (py::isinstance<py::str>(h)) return h.cast<std::string>();
  if (py::isinstance<py::array>(h) || py::hasattr(h, "tolist")) return ToJson(h.attr("tolist")());  // numpy
  if (py::isinstance<py::dict>(h)) {
    nlohmann::json out = nlohmann::json::object();
    for (const auto& [k, v] : h.cast<py::dict>()) {
      if (!py::isinstance<py::str>(k))
        throw py::type_error(fmt::format("dictionary keys must be strings, got {}", py::repr(k).cast<std::string>()));
      out[k.cast<std::string>()] = ToJson(v);
    }
    return out;
  }
  if (py::isinstance<py::list>(h) || py::isinstance<py::tuple>(h)) {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& e : h) out.push_back(ToJson(e));
    return out;
  }
  throw py::type_error(fmt::format("cannot convert {} to JSON", py::repr(h.get_type()).cast<std::string>()));
}

std::vector<double> ToVector(py::handle h, const std::string& what) {
  if (py::isinstance<py::str>(h) || h.is_none())
    throw py::type_error(
        fmt::format("{}: expected a 1-D array of numbers, got {}", what, py::repr(h.get_type()).cast<std::string>()));
  // ensure() converts lists and integer arrays; it returns a null array (error cleared) when it cannot.
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(h);
  if (!a) {
    throw py::type_error(
        fmt::format("{}: expected a 1-D array of numbers, got {}", what, py::repr(h.get_type()).cast<std::string>()));
  }
  int long_dims = 0;
  std::string shape;
  for (py::ssize_t k = 0; k < a.ndim(); ++k) {
    long_dims += a.shape(k) > 1;
    shape += (k ? ", " : "") + std::to_string(a.shape(k));
  }
  if (long_dims > 1 || a.ndim() == 0)
    throw py::value_error(fmt::format("{}: expected a 1-D array (a vector), got shape ({})", what, shape));
  if (a.size() == 0)
    throw py::value_error(fmt::format("{}: the array is empty; a signal needs at least one sample", what));
  std::vector<double> v(a.data(), a.data() + a.size());
  for (std::size_t i = 0; i < v.size(); ++i)
    if (!std::isfinite(v[i]))
      throw py::value_error(
          fmt::format("{}: sample {} is {}; every sample must be a finite number", what, i + 1, v[i]));
  return v;
}

py::array_t<double> ToArray(const std::vector<double>& v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

namespace {

void AddChecked(CsvTable* table, const std::string& what, const std::string& name, std::vector<double> values) {
  if (!table->columns.empty() && values.size() != table->rows())
    throw py::value_error(
        fmt::format("{}: '{}' has {} samples but '{}' has {}; the signals of one recording must have "
                    "the same length",
                    what, name, values.size(), table->names.front(), table->rows()));
  table->add_column(name, std::move(values));
}

// A dict or tuple of arrays as a table of the columns asked for (their lengths checked).
CsvTable TableFromPython(py::handle h, const std::string& what, const std::vector<std::string>& required,
                         const std::vector<std::string>& optional) {
  CsvTable table;
  table.source = what;
  if (py::isinstance<py::tuple>(h)) {
    const auto items = h.cast<py::tuple>();
    if (items.size() < required.size() || items.size() > required.size() + optional.size())
      throw py::value_error(
          fmt::format("{}: a tuple of {} arrays; expected ({})", what, items.size(), DescribeColumns(required, optional)));
    for (std::size_t i = 0; i < items.size(); ++i) {
      const auto& name = i < required.size() ? required[i] : optional[i - required.size()];
      AddChecked(&table, what, name, ToVector(items[i], fmt::format("{}[{}] ({})", what, i, name)));
    }
    return table;
  }
  if (!py::isinstance<py::dict>(h))
    throw py::type_error(
        fmt::format("{}: expected a recording spec string, a dict of arrays ({}) or a tuple of "
                    "arrays, got {}",
                    what, DescribeColumns(required, optional), py::repr(h.get_type()).cast<std::string>()));
  const auto d = h.cast<py::dict>();
  for (const auto& [k, v] : d) {
    const std::string key = py::str(k);
    if (std::find(required.begin(), required.end(), key) == required.end() &&
        std::find(optional.begin(), optional.end(), key) == optional.end())
      throw py::value_error(fmt::format("{}: unknown key '{}'; expected {}", what, key, DescribeColumns(required, optional)));
  }
  for (const auto* names : {&required, &optional})
    for (const auto& name : *names) {
      if (!d.contains(name)) {
        if (names == &required)
          throw py::value_error(fmt::format("{}: no '{}'; expected {}", what, name, DescribeColumns(required, optional)));
        continue;
      }
      AddChecked(&table, what, name, ToVector(d[py::str(name)], fmt::format("{}['{}']", what, name)));
    }
  return table;
}

}  // namespace

CsvTable RecordingFromPython(py::handle h, const std::string& what, const std::vector<std::string>& required,
                             const std::vector<std::string>& optional) {
  if (py::isinstance<py::str>(h)) return read_recording(h.cast<std::string>(), required, optional);
  CsvTable table = TableFromPython(h, what, required, optional);
  if (table.has("t")) CheckTimeColumn(table.column("t"), what, "t");  // as read_recording checks a file's
  return table;
}

nlohmann::json JsonFromPython(py::handle h, const std::string& what) {
  if (!py::isinstance<py::str>(h)) return ToJson(h);
  return ReadJsonFile(h.cast<std::string>(), what);  // the CLI's reader, with its messages
}

void CheckPythonSignals() {
  py::gil_scoped_acquire gil;
  if (PyErr_CheckSignals() != 0) throw py::error_already_set();
}

}  // namespace hw::python

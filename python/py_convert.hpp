#pragma once
// Conversions between Python objects and the engine's inputs and outputs, shared by the module's functions:
// numpy arrays (or sequences) in, plain Python objects out (dict, list, float, int, str, bool, None).
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "core/csv_table.hpp"

namespace hw::python {

namespace py = pybind11;

// JSON values as plain Python objects and back (dicts with string keys, lists, numbers, strings, None;
// numpy arrays and scalars become lists and numbers).
py::object ToPython(const nlohmann::json& j);
nlohmann::json ToJson(py::handle h);

// A signal: a 1-D array-like of real numbers (an Nx1 or 1xN array counts as 1-D), every sample finite.
// Raises ValueError naming `what` otherwise.
std::vector<double> ToVector(py::handle h, const std::string& what);
py::array_t<double> ToArray(const std::vector<double>& v);

// A recording given from Python: a spec string (core/recording.hpp, e.g. "rec.mat:u=vir,y=qm"), a dict
// {"u": array, "y": array, ...} with exactly the columns required (and optional), or a tuple of arrays in
// the order of `required`. Returns a table holding those columns, all of one length.
CsvTable RecordingFromPython(py::handle h, const std::string& what, const std::vector<std::string>& required,
                             const std::vector<std::string>& optional = {});

// A JSON document given as a dict, or as the path of a JSON file.
nlohmann::json JsonFromPython(py::handle h, const std::string& what);

// Raises ValueError(prefix + message) when options.IsValid fails: the CLI reports the same message.
template <typename Options>
void RequireValid(const Options& options, const std::string& prefix = "") {
  std::string error;
  if (!options.IsValid(&error)) throw py::value_error(prefix + error);
}

// Raises ValueError with the message of a failed check the library shares with the CLI (`check(&message)` is
// false for a bad value), e.g. Require([&](std::string* e) { return dss::ValidHorizon(horizon, e); }).
template <typename Check>
void Require(Check&& check) {
  std::string error;
  if (!check(&error)) throw py::value_error(error);
}

// Runs `work` with the GIL released (long engine calls; other Python threads keep running).
template <typename F>
auto WithoutGil(F&& work) {
  py::gil_scoped_release release;
  return work();
}

// Raises KeyboardInterrupt (as pybind11::error_already_set) when Ctrl-C arrived; callable without the GIL.
void CheckPythonSignals();

}  // namespace hw::python

#pragma once
// The Python module `hwbounds`: each py_*.cpp defines one group of functions on the module.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

namespace hw::python {

void DefineRecordings(pybind11::module_& m);  // read_recording
void DefineBounds(pybind11::module_& m);      // bounds
void DefineModels(pybind11::module_& m);      // simulate, pop
void DefineEstimators(pybind11::module_& m);  // brouri_estimate, esmaeilani_estimate
void DefineDiagnose(pybind11::module_& m);    // diagnose, scenario

}  // namespace hw::python

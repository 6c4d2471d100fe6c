// PYBIND11_MODULE(hwbounds): the engine of the `hwbounds` CLI from Python (docs/python.md).
#include "core/input_error.hpp"
#include "python/py_module.hpp"

PYBIND11_MODULE(hwbounds, m) {
  namespace py = pybind11;
  m.doc() =
      "hwbounds: guaranteed parameter bounds, estimators and diagnosis for Hammerstein-Wiener systems "
      "(the engine of the hwbounds CLI; docs/python.md)";
  // Bad input is a ValueError carrying the CLI's message (file, line or variable, what is wrong).
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const hw::InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });
  hw::python::DefineRecordings(m);
  hw::python::DefineBounds(m);
  hw::python::DefineModels(m);
  hw::python::DefineEstimators(m);
  hw::python::DefineDiagnose(m);
}

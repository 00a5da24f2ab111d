// omnical._omnical: the extension behind `import omnical` (omnical/__init__.py adds the
// IntEnum of statuses and re-exports). Errors: the library's InputError becomes
// omnical.InputError (a ValueError) with the same one-line text; a job cancelled by its
// progress callback raises omnical.Cancelled; Ctrl-C during a long call raises
// KeyboardInterrupt once the job has stopped.
#include <glog/logging.h>
#include <pybind11/pybind11.h>

#include "model/input_error.h"
#include "model/progress.h"
#include "tools/python/bindings.h"

PYBIND11_MODULE(_omnical, m) {
  namespace py = pybind11;
  m.doc() = "omnical: calibration and correction of non-central catadioptric cameras (the C++ library's API)";
  m.attr("__version__") = OMNICAL_VERSION;
  // As the CLI (tools/main.cc): Ceres' early-termination lines would print from a library
  // call; the result says what failed.
  FLAGS_minloglevel = google::GLOG_FATAL;
  py::register_exception<omnical::InputError>(m, "InputError", PyExc_ValueError)
      .attr("__doc__") = "Bad input (a file, a field, a value): the library's one-line message naming it. A ValueError.";
  py::register_exception<omnical::Cancelled>(m, "Cancelled", PyExc_RuntimeError)
      .attr("__doc__") = "A long call stopped because its progress callback returned False.";
  omnical::python::BindModel(m);
  omnical::python::BindCalib(m);
  omnical::python::BindCorrection(m);
  omnical::python::BindDesign(m);
}

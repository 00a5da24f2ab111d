#include "tools/python/bindings.h"
#include "tools/python/py_common.h"

namespace omnical::python {

void BindDesign(py::module_& /*m*/) {}

}  // namespace omnical::python

// The module's parts, one per library layer group; module.cc calls them in order.
#pragma once

#include <pybind11/pybind11.h>

namespace omnical::python {

void BindModel(pybind11::module_& m);       // Sensor, projection statuses (bind_model.cc)
void BindCalib(pybind11::module_& m);       // Target, detect, calibrate (bind_calib.cc)
void BindCorrection(pybind11::module_& m);  // parallax, remap tables, unwarp, export_central (bind_correction.cc)
void BindDesign(pybind11::module_& m);      // render, design_ode, design_fit (bind_design.cc)

}  // namespace omnical::python

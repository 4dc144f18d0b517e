// SPDX-License-Identifier: BSD-3-Clause
// rotacal._core: the private extension behind the typed Python package. Each bind_* lives in
// its own file next to this one, one per C++ module.
#include <pybind11/pybind11.h>

#include "rotacal/core/error.hpp"
#ifdef ROTACAL_WITH_HW
#include "rotacal/hw/transport.hpp"
#endif

namespace pyb = pybind11;

namespace rotacal::py {
void bind_kinematics(pyb::module_& m);
void bind_io(pyb::module_& m);
void bind_ballbar(pyb::module_& m);
void bind_fit(pyb::module_& m);
void bind_rtest(pyb::module_& m);
void bind_diagnose(pyb::module_& m);
void bind_ballbar_plan(pyb::module_& m);
void bind_noise(pyb::module_& m);
void bind_controller_export(pyb::module_& m);
void bind_compensation_table(pyb::module_& m);
void bind_design(pyb::module_& m);
void bind_circular(pyb::module_& m);
void bind_probe(pyb::module_& m);
void bind_probe_design_module(pyb::module_& m);
void bind_multi(pyb::module_& m);
void bind_multi_diagnosis(pyb::module_& m);
void bind_realtime(pyb::module_& m);
void bind_thermal(pyb::module_& m);
#ifdef ROTACAL_WITH_HW
void bind_hw(pyb::module_& m);
#endif
}  // namespace rotacal::py

PYBIND11_MODULE(_core, m) {
  m.doc() = "rotacal native core (use the rotacal package, not this module)";
  // Typed exceptions: Python sees rotacal.Error and its subclasses. pybind11 tries the most
  // recently registered translator first, so the base is registered first.
  auto error = pyb::register_exception<rotacal::Error>(m, "Error", PyExc_RuntimeError);
  pyb::register_exception<rotacal::InvalidArgument>(m, "InvalidArgument", error.ptr());
  pyb::register_exception<rotacal::DegenerateGeometry>(m, "DegenerateGeometry", error.ptr());
  pyb::register_exception<rotacal::ParseError>(m, "ParseError", error.ptr());
  auto io_error = pyb::register_exception<rotacal::IoError>(m, "IoError", error.ptr());
#ifndef ROTACAL_WITH_HW
  (void)io_error;
#endif
  rotacal::py::bind_kinematics(m);
  rotacal::py::bind_io(m);
  rotacal::py::bind_ballbar(m);
  rotacal::py::bind_fit(m);
  rotacal::py::bind_noise(m);
  rotacal::py::bind_rtest(m);
  rotacal::py::bind_diagnose(m);
  rotacal::py::bind_ballbar_plan(m);
  rotacal::py::bind_controller_export(m);
  rotacal::py::bind_compensation_table(m);
  rotacal::py::bind_design(m);
  rotacal::py::bind_circular(m);
  rotacal::py::bind_probe(m);
  rotacal::py::bind_probe_design_module(m);
  rotacal::py::bind_multi(m);
  rotacal::py::bind_multi_diagnosis(m);
  rotacal::py::bind_realtime(m);
  rotacal::py::bind_thermal(m);
#ifdef ROTACAL_WITH_HW
  auto serial = pyb::register_exception<rotacal::hw::SerialError>(m, "SerialError", io_error.ptr());
  pyb::register_exception<rotacal::hw::DeviceDisconnected>(m, "DeviceDisconnected", serial.ptr());
  rotacal::py::bind_hw(m);
#endif
}

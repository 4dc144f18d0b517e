// SPDX-License-Identifier: BSD-3-Clause
// Bindings for include/rotacal/kinematics: thin wrappers, numpy in, numpy out.
#include "numpy.hpp"
#include "rotacal/kinematics/effects.hpp"
#include "rotacal/kinematics/machine.hpp"

namespace rotacal::py {

namespace {
LocationErrors<double> errors_of(
    const pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>& e) {
  return LocationErrors<double>(vec_of<8>(e, "errors"));
}
}  // namespace

void bind_kinematics(pyb::module_& m) {
  pyb::class_<MachineType>(m, "MachineType",
                           "A 5-axis machine: a built-in (AC_trt, BC_trt, builtin(name)) or a "
                           "rotacal-machine/1 description (from_description).")
      .def_readonly_static("AC_trt", &MachineType::AC_trt)
      .def_readonly_static("BC_trt", &MachineType::BC_trt)
      .def_static(
          "from_description",
          [](const std::string& json_text, const std::string& source) {
            return MachineType::from_description(parse_machine_description(json_text, source));
          },
          pyb::arg("json_text"), pyb::arg("source") = "machine description",
          "The machine of a rotacal-machine/1 JSON text; errors name `source` and the field.")
      .def_property_readonly("name", [](MachineType t) { return to_string(t); })
      .def_property_readonly("configuration",
                             [](MachineType t) { return t.description().configuration(); })
      .def_property_readonly(
          "axis_names",
          [](MachineType t) {
            return std::string{t.description().axis(0).name, t.description().axis(1).name};
          },
          "Rotary axis letters in chain order (table axes, then head axes): the "
          "session's rotary columns.")
      .def_property_readonly("tilt_axis",
                             [](MachineType t) { return std::string(1, tilt_axis_letter(t)); })
      .def_property_readonly("rot_axis",
                             [](MachineType t) { return std::string(1, rot_axis_letter(t)); })
      .def_property_readonly("has_head", &MachineType::has_head)
      .def_property_readonly("is_builtin", &MachineType::is_builtin)
      .def_property_readonly(
          "description_json",
          [](MachineType t) { return machine_description_json(t.description()); })
      .def("__eq__", [](MachineType a, MachineType b) { return a == b; })
      .def("__ne__", [](MachineType a, MachineType b) { return a != b; })
      .def("__hash__", [](MachineType t) { return t.id(); })
      .def(pyb::pickle([](MachineType t) { return machine_description_json(t.description()); },
                       [](const std::string& json_text) {
                         return MachineType::from_description(
                             parse_machine_description(json_text, "pickle"));
                       }))
      .def("__repr__", [](MachineType t) {
        if (t == MachineType::AC_trt) return std::string("MachineType.AC_trt");
        if (t == MachineType::BC_trt) return std::string("MachineType.BC_trt");
        return "MachineType('" + to_string(t) + "')";
      });
  m.def("parse_machine_type", &parse_machine_type, pyb::arg("text"),
        "A built-in machine by its name ('AC-trt', 'BC-trt', 'B-head-C-table', ...).");
  m.def("builtin_machine_names", &builtin_machine_names, "Names of the built-in machines.");
  m.def("machine_name", pyb::overload_cast<MachineType>(&to_string), pyb::arg("machine"));
  m.def("location_error_names", &location_error_names, pyb::arg("machine"),
        "ISO 230-7 names of the 8 location errors, in the order of every errors vector.");

  pyb::class_<Effect>(m, "Effect", "One entry of the effects catalogue (shared/spec/effects.md).")
      .def(pyb::init(&Effect::parse), pyb::arg("id"), "Parse a catalogue id such as 'coning_B'.")
      .def_property_readonly("id", &Effect::id)
      .def_property_readonly("cause", &Effect::cause)
      .def_property_readonly("num_params", &Effect::num_params)
      .def_property_readonly("param_names", &Effect::param_names)
      .def_property_readonly("param_units", &Effect::param_units)
      .def_readonly("harmonic", &Effect::harmonic)
      .def("applies_to", &Effect::applies_to, pyb::arg("machine"))
      .def("__repr__", [](const Effect& e) { return "Effect('" + e.id() + "')"; })
      .def("__eq__", [](const Effect& a, const Effect& b) { return a == b; });
  m.def("effect_catalogue", &effect_catalogue, pyb::arg("machine"), pyb::arg("max_harmonic") = 4,
        "Every catalogue entry that applies to the machine, harmonics 1..max_harmonic.");

  m.def(
      "forward",
      [](MachineType machine,
         const pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>& errors,
         const pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>& angles,
         const pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>& q_table) {
        const auto e = errors_of(errors);
        const auto a = rows_of<2>(angles, "angles");
        const auto q = rows_of<3>(q_table, "q_table");
        if (a.rows() != q.rows())
          throw InvalidArgument("forward: angles and q_table must have the same number of rows");
        Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> p(q.rows(), 3);
        for (Eigen::Index i = 0; i < q.rows(); ++i)
          p.row(i) =
              forward<double>(machine, e, {a(i, 0), a(i, 1)}, q.row(i).transpose()).transpose();
        return p;
      },
      pyb::arg("machine"), pyb::arg("errors"), pyb::arg("angles"), pyb::arg("q_table"),
      R"doc(Machine-frame positions of table points.

Parameters
----------
machine : MachineType
errors : (8,) location errors, order of location_error_names (mm, rad)
angles : (N, 2) tilt and C angles, rad
q_table : (N, 3) points in the table frame, mm

Returns
-------
(N, 3) machine-frame positions, mm)doc");
}

}  // namespace rotacal::py

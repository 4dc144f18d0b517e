// SPDX-License-Identifier: BSD-3-Clause
// Bindings for include/rotacal/io/controller_export.hpp (controller exports of a model file)
// and io/controller_comment.hpp (free text as comments of the files a controller executes).
#include "rotacal/io/controller_export.hpp"

#include <pybind11/stl.h>

#include "numpy.hpp"
#include "rotacal/io/ballbar_file.hpp"
#include "rotacal/io/controller_comment.hpp"
#include "rotacal/io/thermal_model.hpp"

namespace rotacal::py {

namespace {

// The export of a thermal model at a lag state: at a time of the test's duty, or given.
ControllerExport export_thermal(Controller c, const std::string& model_path,
                                const std::optional<std::string>& current_text,
                                const std::string& current_source, int toolholder,
                                const std::string& generated_at, std::optional<double> at_s,
                                const std::optional<std::vector<double>>& state) {
  if (at_s && state) throw InvalidArgument("--at and --state: give one of them");
  if (at_s && !(*at_s >= 0.0 && *at_s <= 1e8))
    throw InvalidArgument("--at: a time of the test duty, 0 to 1e8 s from its first row");
  const ThermalModel m = read_thermal_model(model_path);
  const ThermalErrorsAt at =
      at_s ? thermal_errors_at_time(m, m.test_heat, m.test_heat.start.front() + *at_s)
           : thermal_errors_at_state(m, *state);
  std::string words;
  for (std::size_t l = 0; l < at.y.size(); ++l)
    words += (l ? ", y" : "y") + std::to_string(l + 1) + " = " + format_number(at.y[l]);
  if (at_s) words += " (" + format_number(*at_s) + " s of the test duty from its first row)";
  ExportOptions o;
  o.toolholder = toolholder;
  o.generated_at = generated_at;
  if (current_text) {
    o.current = parse_current_parameters(c, m.machine, *current_text, current_source, toolholder);
    o.current_given = true;
  }
  return export_kinematics(c, thermal_export_input(m, at, model_path, words), o);
}

}  // namespace

void bind_controller_export(pyb::module_& m) {
  pyb::class_<ControllerValue>(m, "ControllerValue", "One controller parameter as written.")
      .def_readonly("name", &ControllerValue::name)
      .def_readonly("current", &ControllerValue::current,
                    "active while the test ran (0 when not given)")
      .def_readonly("corrected", &ControllerValue::corrected)
      .def_readonly("std", &ControllerValue::std, "1 sigma of corrected, controller units")
      .def_readonly("unit", &ControllerValue::unit)
      .def_readonly("source", &ControllerValue::from, "the location errors it carries");
  pyb::class_<ErrorDisposition>(m, "ErrorDisposition",
                                "Whether a location error reaches the controller.")
      .def_readonly("name", &ErrorDisposition::name)
      .def_readonly("value", &ErrorDisposition::value)
      .def_readonly("std", &ErrorDisposition::std)
      .def_readonly("observable", &ErrorDisposition::observable)
      .def_readonly("held", &ErrorDisposition::held)
      .def_readonly("where", &ErrorDisposition::where);
  pyb::class_<ControllerExport>(m, "ControllerExport",
                                "A model's location errors in a controller's parameters.")
      .def_property_readonly("controller",
                             [](const ControllerExport& e) { return to_string(e.controller); })
      .def_readonly("kinematics", &ControllerExport::kinematics)
      .def_readonly("current_given", &ControllerExport::current_given)
      .def_readonly("values", &ControllerExport::values)
      .def_readonly("errors", &ControllerExport::errors)
      .def_property_readonly(
          "not_held", [](const ControllerExport& e) { return Eigen::VectorXd(e.not_held.v); },
          "(8,) errors the controller cannot hold (mm, rad): NC compensation")
      .def_readonly("text", &ControllerExport::text, "the file to load on the controller")
      .def_readonly("file_kind", &ControllerExport::file_kind);
  m.def(
      "export_controller",
      [](const std::string& model_path, const std::string& controller,
         std::optional<std::string> current_text, const std::string& current_source, int toolholder,
         const std::string& generated_at, std::optional<double> thermal_at_s,
         std::optional<std::vector<double>> thermal_state) {
        const Controller c = parse_controller(controller);
        if (thermal_at_s || thermal_state)  // a thermal model at a lag state (io/thermal_model.hpp)
          return export_thermal(c, model_path, current_text, current_source, toolholder,
                                generated_at, thermal_at_s, thermal_state);
        const ModelFile model = read_model(model_path);
        ExportOptions o;
        o.toolholder = toolholder;
        o.generated_at = generated_at;
        if (current_text) {
          o.current =
              parse_current_parameters(c, model.machine, *current_text, current_source, toolholder);
          o.current_given = true;
        }
        return export_kinematics(c, export_input(model, model_path), o);
      },
      pyb::arg("model_path"), pyb::arg("controller"), pyb::arg("current_text") = std::nullopt,
      pyb::arg("current_source") = "<current>", pyb::arg("toolholder") = 1,
      pyb::arg("generated_at") = "", pyb::arg("thermal_at_s") = std::nullopt,
      pyb::arg("thermal_state") = std::nullopt,
      "Export a model file's location errors into a controller's kinematic parameters "
      "(io/controller_export.hpp); current_text: the controller's current values (its HAL/MPF file "
      "or the documented JSON), None for zero offsets. A thermal model at thermal_at_s (s of the "
      "test's duty from its first row) or at thermal_state (y per lag): its errors there.");
  m.def(
      "comment_lines",
      [](const std::string& dialect, const std::string& text) {
        return comment_lines(parse_comment_dialect(dialect), text);
      },
      pyb::arg("dialect"), pyb::arg("text"),
      "text as whole comment lines of a file a controller executes (io/controller_comment.hpp), "
      "without line ends; dialect: linuxcnc, fanuc, heidenhain, siemens, isg or hash (HAL, "
      "parameter lists). Every free text written into such a file goes through it.");
  m.def(
      "controller_parameter_names",
      [](const std::string& controller, MachineType machine, int toolholder) {
        return current_parameter_names(parse_controller(controller), machine, toolholder);
      },
      pyb::arg("controller"), pyb::arg("machine"), pyb::arg("toolholder") = 1,
      "The names of the current values an export reads, in the order it writes them.");
}

}  // namespace rotacal::py

// SPDX-License-Identifier: BSD-3-Clause
// Bindings for include/rotacal/io/angle_map.hpp and io/compensation_table.hpp (the errors that
// move with a rotary axis, and the controller tables written from them).
#include "rotacal/io/compensation_table.hpp"

#include <pybind11/stl.h>

#include "numpy.hpp"
#include "rotacal/compensation/axis_errors.hpp"
#include "rotacal/io/angle_map.hpp"

namespace rotacal::py {

void bind_table_writers(pyb::module_& m);

void bind_compensation_table(pyb::module_& m) {
  pyb::class_<AxisAngleMap>(m, "AxisAngleMap", "One rotary axis' error terms at equal spacing.")
      .def_property_readonly("axis", [](const AxisAngleMap& a) { return std::string(1, a.axis); })
      .def_readonly("names", &AxisAngleMap::names, "E_X<axis> .. E_C<axis>, positioning_<axis>")
      .def_readonly("units", &AxisAngleMap::units)
      .def_readonly("sources", &AxisAngleMap::sources, "the model's terms that feed it")
      .def_readonly("notes", &AxisAngleMap::notes, "what the map leaves out")
      .def_readonly("angle_deg", &AxisAngleMap::angle_deg)
      .def_property_readonly(
          "values", [](const AxisAngleMap& a) { return Eigen::MatrixXd(a.values); },
          "(n, 7) the terms at angle_deg (mm, rad)")
      .def_property_readonly(
          "max_interpolation_error",
          [](const AxisAngleMap& a) { return Eigen::VectorXd(a.max_interpolation_error); },
          "(7,) worst absolute difference of the model and the linear interpolation between the "
          "points")
      .def_readonly("samples_between", &AxisAngleMap::samples_between);
  m.def(
      "angle_maps",
      [](const std::string& model_path, double lo_deg, double hi_deg, double spacing_deg,
         int samples_between) {
        const ModelFile model = read_model(model_path);
        std::vector<AxisAngleMap> out;
        for (const AxisErrorFunction& f : axis_error_functions(model, model_path))
          out.push_back(sample_angle_map(f, lo_deg, hi_deg, spacing_deg, samples_between));
        return out;
      },
      pyb::arg("model_path"), pyb::arg("lo_deg"), pyb::arg("hi_deg"), pyb::arg("spacing_deg"),
      pyb::arg("samples_between") = 16,
      "The position-dependent errors of a model file's table axes as functions of each axis' "
      "angle (io/angle_map.hpp), sampled from lo_deg to hi_deg.");
  pyb::class_<FanucPitchOptions>(m, "FanucPitchOptions",
                                 "FANUC pitch error compensation: the control's units and limits.")
      .def(pyb::init<>())
      .def_readwrite("detection_unit_deg", &FanucPitchOptions::detection_unit_deg)
      .def_readwrite("first_number", &FanucPitchOptions::first_number)
      .def_readwrite("last_number", &FanucPitchOptions::last_number)
      .def_readwrite("max_value", &FanucPitchOptions::max_value)
      .def_readwrite("magnification", &FanucPitchOptions::magnification,
                     "parameter 3623; 0: the smallest of 1..100 that keeps the values in range");
  pyb::class_<CompensationTable>(m, "CompensationTable", "One joint's compensation table.")
      .def_property_readonly("axis",
                             [](const CompensationTable& t) { return std::string(1, t.axis); })
      .def_readonly("joint", &CompensationTable::joint)
      .def_readonly("file_name", &CompensationTable::file_name)
      .def_readonly("text", &CompensationTable::text)
      .def_readonly("nominal_deg", &CompensationTable::nominal_deg)
      .def_readonly("value_deg", &CompensationTable::value_deg, "the values written, deg")
      .def_readonly("max_interpolation_error_deg", &CompensationTable::max_interpolation_error_deg)
      .def_readonly("summary", &CompensationTable::summary)
      .def_readonly("holds", &CompensationTable::holds,
                    "the model's terms the table holds (a residual model zeroes them)")
      .def_property_readonly(
          "value_mm",
          [](const CompensationTable& t) {
            std::map<std::string, std::vector<double>> out;
            for (const auto& [k, v] : t.value_mm) out[std::string(1, k)] = v;
            return out;
          },
          "a cross table: the correction of each output axis X, Y, Z at nominal_deg, mm")
      .def_readonly("max_interpolation_error_mm", &CompensationTable::max_interpolation_error_mm);
  pyb::class_<CompensationTables>(m, "CompensationTables", "A controller's tables of a model.")
      .def_readonly("tables", &CompensationTables::tables)
      .def_readonly("ini", &CompensationTables::ini, "the INI lines that load them")
      .def_readonly("not_held", &CompensationTables::not_held);
  bind_table_writers(m);
}

// The writers of io/compensation_table.hpp, each with the options it reads.
void bind_table_writers(pyb::module_& m) {
  const auto options = [](const std::string& model_path, double spacing_deg,
                          const std::map<std::string, std::array<double, 2>>& range_deg,
                          const std::map<std::string, std::string>& file_names,
                          const std::map<std::string, std::string>& axis_names,
                          std::size_t max_points, const std::string& generated_at) {
    CompensationTableOptions o;
    o.spacing_deg = spacing_deg;
    const auto letter = [](const std::string& k) {
      if (k.size() != 1) throw InvalidArgument("axis '" + k + "': one letter A, B, C, X, Y or Z");
      return k[0];
    };
    for (const auto& [k, v] : range_deg) o.range_deg[letter(k)] = v;
    for (const auto& [k, v] : file_names) o.file_names[letter(k)] = v;
    for (const auto& [k, v] : axis_names) o.axis_names[letter(k)] = v;
    o.max_points = max_points;
    o.model_path = model_path;
    o.generated_at = generated_at;
    return o;
  };
  using Ranges = std::map<std::string, std::array<double, 2>>;
  using Names = std::map<std::string, std::string>;
  m.def(
      "linuxcnc_comp_tables",
      [options](const std::string& model_path, double spacing_deg, const Ranges& range_deg,
                const Names& file_names, std::size_t max_points, const std::string& generated_at) {
        const ModelFile model = read_model(model_path);
        return linuxcnc_comp_tables(
            model, axis_error_functions(model, model_path),
            options(model_path, spacing_deg, range_deg, file_names, {}, max_points, generated_at));
      },
      pyb::arg("model_path"), pyb::arg("spacing_deg") = 5.0, pyb::arg("range_deg") = Ranges{},
      pyb::arg("file_names") = Names{}, pyb::arg("max_points") = 0, pyb::arg("generated_at") = "",
      "LinuxCNC COMP_FILEs (type 1) of each table axis' positioning error and the INI lines "
      "that load them (io/compensation_table.hpp); max_points 0: LinuxCNC's 256.");
  m.def(
      "sinumerik_eec_tables",
      [options](const std::string& model_path, double spacing_deg, const Ranges& range_deg,
                const Names& axis_names, std::size_t max_points, const std::string& generated_at) {
        const ModelFile model = read_model(model_path);
        return sinumerik_eec_tables(
            model, axis_error_functions(model, model_path),
            options(model_path, spacing_deg, range_deg, {}, axis_names, max_points, generated_at));
      },
      pyb::arg("model_path"), pyb::arg("spacing_deg") = 5.0, pyb::arg("range_deg") = Ranges{},
      pyb::arg("axis_names") = Names{}, pyb::arg("max_points") = 0, pyb::arg("generated_at") = "",
      "SINUMERIK EEC programs ($AA_ENC_COMP) of each table axis' positioning error "
      "(io/compensation_table.hpp); max_points 0: 200 (808D), else MD38000 as configured.");
  m.def(
      "sinumerik_tables",
      [options](const std::string& model_path, double spacing_deg, const Ranges& range_deg,
                const Names& axis_names, std::size_t max_points, std::size_t max_cross_points,
                const std::string& generated_at) {
        const ModelFile model = read_model(model_path);
        CompensationTableOptions o =
            options(model_path, spacing_deg, range_deg, {}, axis_names, max_points, generated_at);
        o.max_cross_points = max_cross_points;
        return sinumerik_tables(model, axis_error_functions(model, model_path), o);
      },
      pyb::arg("model_path"), pyb::arg("spacing_deg") = 5.0, pyb::arg("range_deg") = Ranges{},
      pyb::arg("axis_names") = Names{}, pyb::arg("max_points") = 0,
      pyb::arg("max_cross_points") = 0, pyb::arg("generated_at") = "",
      "SINUMERIK EEC programs of each table axis' positioning error and CEC programs of its "
      "translations (io/compensation_table.hpp); max_points 0: 200, else MD38000; "
      "max_cross_points 0: 200, else MD18342.");
  m.def(
      "isg_tables",
      [options](const std::string& model_path, double spacing_deg, const Ranges& range_deg,
                const std::map<std::string, int>& axis_numbers, std::size_t max_points,
                std::size_t max_cross_points, const std::string& generated_at) {
        const ModelFile model = read_model(model_path);
        CompensationTableOptions o =
            options(model_path, spacing_deg, range_deg, {}, {}, max_points, generated_at);
        o.max_cross_points = max_cross_points;
        for (const auto& [k, v] : axis_numbers) {
          if (k.size() != 1 || std::string("XYZABC").find(k[0]) == std::string::npos)
            throw InvalidArgument("--isg-axis '" + k + "': one letter X, Y, Z, A, B or C");
          o.isg_axis_numbers[k[0]] = v;
        }
        return isg_tables(model, axis_error_functions(model, model_path), o);
      },
      pyb::arg("model_path"), pyb::arg("spacing_deg") = 5.0, pyb::arg("range_deg") = Ranges{},
      pyb::arg("axis_numbers") = std::map<std::string, int>{}, pyb::arg("max_points") = 0,
      pyb::arg("max_cross_points") = 0, pyb::arg("generated_at") = "",
      "ISG compensation value lists: kw.ssfk of each table axis' positioning error, kw.crosscomp "
      "of its translations (io/compensation_table.hpp); max_points 0: kw_nr_max 1500; "
      "max_cross_points 0: 1000.");
  m.def(
      "fanuc_pitch_tables",
      [options](const std::string& model_path, double spacing_deg, const Ranges& range_deg,
                const FanucPitchOptions& fanuc, const std::string& generated_at) {
        const ModelFile model = read_model(model_path);
        CompensationTableOptions o =
            options(model_path, spacing_deg, range_deg, {}, {}, 0, generated_at);
        o.fanuc = fanuc;
        return fanuc_pitch_tables(model, axis_error_functions(model, model_path), o);
      },
      pyb::arg("model_path"), pyb::arg("spacing_deg") = 5.0, pyb::arg("range_deg") = Ranges{},
      pyb::arg("fanuc") = FanucPitchOptions{}, pyb::arg("generated_at") = "",
      "FANUC pitch error compensation data (parameters 3620-3625 and values by data number) of "
      "each table axis' positioning error (io/compensation_table.hpp).");
}

}  // namespace rotacal::py

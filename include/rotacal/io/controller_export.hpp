// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Identified location errors written into a controller's own kinematic parameters
/// (docs/controller_exports.md has the mapping field by field, with its sources).
///
/// The errors are relative to the kinematics that was active while the test ran: an export
/// takes the controller's current values (zero offsets when none are given, and says so) and
/// writes corrected ones. What a controller cannot hold (LinuxCNC's trivial kinematics has no
/// orientation terms) is not dropped: it is listed with its value, and stays available as NC
/// compensation (`rotacal compensate`).
///
/// Machines: AC-trt and BC-trt (tilting-rotary tables), axes turning as in
/// ../shared/spec/formats.md (right-handed about +X/+Y/+Z).

#include <Eigen/Core>
#include <array>
#include <map>
#include <string>
#include <vector>

#include "rotacal/io/model_file.hpp"
#include "rotacal/io/thermal_model.hpp"
#include "rotacal/kinematics/machine.hpp"

namespace rotacal {

enum class Controller {
  linuxcnc,    ///< xyzac-trt-kins / xyzbc-trt-kins HAL pins (src/emc/kinematics/trtfuncs.c)
  siemens,     ///< SINUMERIK orientable toolholder $TC_CARR, kinematic type P (W1 manual)
  isg,         ///< ISG/Beckhoff universal kinematic (ID 91): per-axis POINT and ORIENTATION
  heidenhain,  ///< TNC kinematics table: the Trans rows before each rotary MachAxis (mapping only)
  fanuc,       ///< 30i TCP parameters 19700-19705 of a two-table machine (mapping only)
};

/// "linuxcnc", "siemens", "isg", "heidenhain", "fanuc"; InvalidArgument naming `option` otherwise.
Controller parse_controller(const std::string& name, const std::string& option = "--controller");
std::string to_string(Controller c);

/// What the export knows of the identification.
struct ExportInput {
  MachineType machine = MachineType::AC_trt;
  LocationErrors<double> errors;  ///< mm, rad
  std::array<bool, 8> observable{
      true, true, true, true,
      true, true, true, true};  ///< false: not determined; its parameters keep the current value
  Eigen::Matrix<double, 8, 8> covariance = Eigen::Matrix<double, 8, 8>::Zero();  ///< of the errors
  bool full_covariance = false;  ///< false: only the diagonal (each error's std) is known
  std::string source;            ///< the session and date the model names, for the header
  std::string model_path;        ///< the model file, for the header
};

/// The export input of a model file: errors, their covariance (the model's `covariance` member
/// when it lists them, else the diagonal of their std), observability and `source`.
ExportInput export_input(const ModelFile& model, const std::string& model_path);

/// One controller parameter as written.
struct ControllerValue {
  std::string
      name;  ///< as the controller spells it ("y-offset", "$TC_CARR5[1]", "P-CHAN-00293 ...")
  double current = 0.0;    ///< active while the test ran (0 when not given)
  double corrected = 0.0;  ///< written
  double std = 0.0;        ///< 1 sigma of `corrected` from the identification (controller units)
  std::string unit;
  std::string from;  ///< the location errors it carries ("E_Y0A - E_Y0C"), empty if none
};

/// Whether one location error reaches the controller.
struct ErrorDisposition {
  std::string name;
  double value = 0.0;
  double std = 0.0;
  bool observable = true;
  bool held = false;  ///< written into the parameters
  std::string where;  ///< the parameters that hold it, or why it is not held
};

struct ControllerExport {
  Controller controller = Controller::linuxcnc;
  std::string kinematics;  ///< "xyzac-trt-kins", "$TC_CARR type P", ...
  bool current_given = false;
  std::vector<ControllerValue> values;
  std::vector<ErrorDisposition> errors;
  LocationErrors<double>
      not_held;           ///< the errors the controller cannot hold (mm, rad): NC compensation
  std::string text;       ///< the file to load on the controller
  std::string file_kind;  ///< "HAL", "MPF", ... for people
};

struct ExportOptions {
  /// The controller's values active during the test, by the names ControllerValue uses
  /// (parse_current_parameters reads them from the controller's own file or JSON).
  std::map<std::string, double> current;
  bool current_given = false;
  int toolholder = 1;        ///< Siemens: the $TC_CARR data set number
  std::string generated_at;  ///< UTC time for the header (empty: now)
};

/// The export. Throws InvalidArgument when the current values are not a kinematics of this
/// machine (a Siemens axis vector far from its nominal axis, an unknown parameter name).
ControllerExport export_kinematics(Controller controller, const ExportInput& input,
                                   const ExportOptions& options = {});

/// The names of the current values a controller's export uses, in the order they are written.
std::vector<std::string> current_parameter_names(Controller controller, MachineType machine,
                                                 int toolholder = 1);

/// Current values from the controller's own text (LinuxCNC: `setp <kins>.<pin> <value>` lines
/// of a HAL file; Siemens: `$TC_CARRn[k]=value` lines of an MPF) or from the small JSON
/// `{"controller": "...", "parameters": {"name": value, ...}}` (any controller;
/// docs/controller_exports.md). Unknown names are refused, naming `source` and the line.
std::map<std::string, double> parse_current_parameters(Controller controller, MachineType machine,
                                                       const std::string& text,
                                                       const std::string& source,
                                                       int toolholder = 1);

/// The export input of the errors at a state: values, covariance and observability of `at`,
/// the source of the file with `state` (words, e.g. "y1 = 0.81: 2 h of the test duty") added.
ExportInput thermal_export_input(const ThermalModel& m, const ThermalErrorsAt& at,
                                 const std::string& model_path, const std::string& state);

}  // namespace rotacal

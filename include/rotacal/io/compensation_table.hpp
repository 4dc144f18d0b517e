// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Controller compensation tables of the errors that move with a rotary axis (angle_map.hpp):
/// `rotacal export --tables`. docs/controller_exports.md has each format with its sources and
/// its sign; the tests implement each controller's documented table semantics and read only the
/// files written here.
///
/// LinuxCNC 2.9 `[JOINT_n]COMP_FILE` (src/emc/motion/usrmotintf.cc usrmotLoadComp, command.c
/// EMCMOT_SET_JOINT_COMP, control.c compute_screw_comp): lines `nominal fwd rev` read up to the
/// first line that is not three numbers; with COMP_FILE_TYPE = 1 the two values are trims the
/// motion controller adds to the motor command (moving up, moving down), linear between the
/// nominal positions, the end values held beyond them, looked up on the joint position without
/// modulo; at most 256 lines (EMCMOT_COMP_SIZE); BACKLASH is not used while a table is loaded.

#include <array>
#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "rotacal/io/angle_map.hpp"
#include "rotacal/io/model_file.hpp"

namespace rotacal {

struct CompensationTableOptions {
  double spacing_deg = 5.0;  ///< between table points
  /// The angles each table spans, by axis letter (deg). Default: the axis' limits; an endless
  /// axis -360..360 (the table is looked up without modulo: the header says where it stops).
  std::map<char, std::array<double, 2>> range_deg;
  /// Most points a table may hold; 0: the controller's own (LinuxCNC 256, EMCMOT_COMP_SIZE in
  /// src/emc/motion/motion.h; SINUMERIK 200, the 808D's, else MD38000 as configured).
  std::size_t max_points = 0;
  /// SINUMERIK: the machine axis identifier of each axis letter (MD10000; default "<letter>1").
  std::map<char, std::string> axis_names;
  int samples_between = 63;  ///< model evaluations inside each interval for the error
  /// The file each table is written to, by axis letter, for the INI lines (default
  /// "comp_<axis>.txt").
  std::map<char, std::string> file_names;
  std::string model_path;    ///< for the header
  std::string generated_at;  ///< UTC time for the header (empty: now)
};

/// One joint's table.
struct CompensationTable {
  char axis = 'C';
  int joint = 0;          ///< LinuxCNC joint number ([JOINT_n])
  std::string file_name;  ///< as the INI lines name it
  std::string text;       ///< the file
  /// The table's positions and the values written (LinuxCNC: the trims; SINUMERIK: the EEC
  /// values), deg.
  std::vector<double> nominal_deg, value_deg;
  double max_interpolation_error_deg = 0.0;  ///< worst |exact value - interpolated value|
  /// The model's terms the table holds (effect ids, R-test map coefficients): a residual model
  /// for `rotacal compensate` sets them to zero.
  std::vector<std::string> holds;
  std::string summary;  ///< one line for people
};

struct CompensationTables {
  std::vector<CompensationTable> tables;
  std::string ini;  ///< the INI lines that load them
  /// The model's terms no table holds, with their largest value: "E_XC: 1.2 um (... )".
  std::vector<std::string> not_held;
};

/// LinuxCNC COMP_FILEs (COMP_FILE_TYPE = 1) of each table axis' positioning error, from the
/// model's axis functions (compensation/axis_errors.hpp: axis_error_functions(model, path)), joints
/// numbered as xyzac-trt-kins / xyzbc-trt-kins (tilt 3, C 4). The trim at nominal angle p
/// is what makes the model's axis reach p: t = -positioning(p + t) (solved by iteration), in
/// deg. Throws InvalidArgument naming the limit or option when a table would have more than
/// max_points lines, a range or spacing is not usable, the machine has an axis on the head,
/// or the model holds no positioning error of any table axis.
CompensationTables linuxcnc_comp_tables(const ModelFile& model,
                                        const std::vector<AxisErrorFunction>& functions,
                                        const CompensationTableOptions& options);

/// SINUMERIK encoder / leadscrew error compensation (EEC, K3 function manual "Interpolatory
/// compensation"; 808D function manual "LEC") of each table axis' positioning error: one
/// program per axis, `%_N_AX_EEC_INI`, `$AA_ENC_COMP[0,N,<axis>]` values in deg, linear between
/// equidistant points from `$AA_ENC_COMP_MIN` every `$AA_ENC_COMP_STEP` to `$AA_ENC_COMP_MAX`,
/// the end values held beyond them, or repeated with `$AA_ENC_COMP_IS_MODULO = 1`. The control
/// corrects the actual value by the table's value, so a positive value moves the axis negative:
/// the value at axis position x is the positioning error there (actual - commanded angle). An
/// endless axis without a range gets a modulo table 0..360 deg. Refused as
/// linuxcnc_comp_tables, naming MD38000 for too many points (`ini` stays empty).
CompensationTables sinumerik_eec_tables(const ModelFile& model,
                                        const std::vector<AxisErrorFunction>& functions,
                                        const CompensationTableOptions& options);

}  // namespace rotacal

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

/// FANUC pitch error compensation (parameter manual, parameters 3620-3627): the data numbers,
/// units and limits of the control. The defaults are a 0i's; other series hold other ranges.
struct FanucPitchOptions {
  double detection_unit_deg = 0.001;  ///< the axis' detection unit (IS-B: 0.001 deg)
  int first_number = 0;               ///< the first data number of the first table written
  int last_number = 1023;             ///< the highest data number the control holds
  int max_value = 127;                ///< the largest absolute value one data number holds
  /// Parameter 3623: values are in detection units times it. 0: the smallest of 1..100 that
  /// keeps every value within max_value.
  int magnification = 0;
};

struct CompensationTableOptions {
  double spacing_deg = 5.0;  ///< between table points
  /// The angles each table spans, by axis letter (deg). Default: the axis' limits; an endless
  /// axis -360..360 (the table is looked up without modulo: the header says where it stops).
  std::map<char, std::array<double, 2>> range_deg;
  /// Most points a table may hold; 0: the controller's own (LinuxCNC 256, EMCMOT_COMP_SIZE in
  /// src/emc/motion/motion.h; SINUMERIK 200, the 808D's, else MD38000 as configured).
  std::size_t max_points = 0;
  /// Most points a cross table may hold; 0: the controller's own (SINUMERIK 200, the 828D's,
  /// else MD18342 $MN_MM_CEC_MAX_POINTS as configured; ISG 1000, kw.crosscomp.table).
  std::size_t max_cross_points = 0;
  /// SINUMERIK: the machine axis identifier of each axis letter (MD10000; default "<letter>1").
  std::map<char, std::string> axis_names;
  int samples_between = 63;  ///< model evaluations inside each interval for the error
  /// The file each table is written to, by axis letter, for the INI lines (default
  /// "comp_<axis>.txt").
  std::map<char, std::string> file_names;
  /// ISG: the logical axis number of each axis letter (kopf, kw.crosscomp.master_ax_nr;
  /// default X 1, Y 2, Z 3, A 4, B 5, C 6).
  std::map<char, int> isg_axis_numbers;
  std::string model_path;    ///< for the header
  std::string generated_at;  ///< UTC time for the header (empty: now)
  FanucPitchOptions fanuc;
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
  /// A cross table (SINUMERIK CEC, ISG kw.crosscomp): the value of each output axis X, Y, Z at
  /// nominal_deg, mm, the correction added to that linear axis' position; empty for a
  /// positioning table.
  std::map<char, std::vector<double>> value_mm;
  double max_interpolation_error_mm = 0.0;  ///< a cross table's worst error, over its outputs
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

/// SINUMERIK tables: the EEC tables of sinumerik_eec_tables and, per table axis with a
/// translation E_X, E_Y or E_Z, a cross error compensation program (CEC, K3 "Sag compensation",
/// `%_N_NC_CEC_INI`): one table per output axis, `$AN_CEC[t,N]` values in mm at the input axis'
/// positions `$AN_CEC_MIN + N $AN_CEC_STEP` up to `$AN_CEC_MAX`, linear between them, the end
/// values held beyond (or modulo), both directions, no table multiplication. A table's value is
/// added to its output axis' position: it is the axis' translation E there, which moves the
/// table point, so the tool follows it. The translations are those of the frame the axis is
/// mounted in (angle_map.hpp): the tilt axis' hold at any rotary angle, the rotary axis' at tilt
/// 0 only (the header says so and gives what remains over the tilt range; `not_held` too).
/// Tables are numbered from 0 over the files. Refused as sinumerik_eec_tables, naming MD18342
/// for a cross table over max_cross_points.
CompensationTables sinumerik_tables(const ModelFile& model,
                                    const std::vector<AxisErrorFunction>& functions,
                                    const CompensationTableOptions& options);

/// ISG/Beckhoff compensation value lists (TF5200 axis compensation): per table axis with a
/// positioning error a leadscrew error compensation list `ssfk_<axis>.lis` (kw.ssfk: equidistant
/// from kw_startpos every interval, 0.0001 deg, the values actual - commanded position, which the
/// control takes off the setpoint, bilateral with the same values both ways, kw.ssfk.modulo over
/// one turn for an endless axis without a range, linear between points, end values held), and
/// per linear axis X, Y, Z that a table axis translates a cross compensation list
/// `crosscomp_<slave>.lis` (kw.crosscomp: the master's positions, the corrections in 0.1 um
/// added to the slave's position, no modulo) of the master with the largest translation along it:
/// a slave's list holds one master, the others' are in `not_held`. The angular error motions are
/// not held (ISG's Volumetric Compensation would hold them; not written). Refused as
/// sinumerik_eec_tables, naming kw_nr_max (default 1500, `max_points`) or kw.crosscomp's 1000
/// values (`max_cross_points`).
CompensationTables isg_tables(const ModelFile& model,
                              const std::vector<AxisErrorFunction>& functions,
                              const CompensationTableOptions& options);

/// FANUC pitch error compensation data of each table axis' positioning error: per axis a
/// listing of the parameters 3620-3625 and the values by data number, to enter on the pitch
/// error compensation screen. The value of data number R+k is the compensation of the section
/// from (k-1) to k intervals past the reference position (at 0 deg), incremental, in detection
/// units times the magnification; the control adds their sum to the motor command, so the
/// absolute compensation at a point is the trim nominal - actual relative to the reference
/// position's (linuxcnc_comp_tables' sign). An endless axis without a range gets one turn: the
/// values sum to zero and the reference number holds the last one's value. The trim at the
/// reference position is not in the table (the compensation is zero there): the header gives
/// it. Refused as linuxcnc_comp_tables, and naming the limit for a value beyond max_value at
/// every magnification, data numbers beyond last_number, a spacing that is no multiple of the
/// detection unit or does not divide a turn, and a model whose turn does not sum to zero.
CompensationTables fanuc_pitch_tables(const ModelFile& model,
                                      const std::vector<AxisErrorFunction>& functions,
                                      const CompensationTableOptions& options);

}  // namespace rotacal

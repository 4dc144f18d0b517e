// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Compensation of identified location errors and its verification by re-measurement
/// (Flynn et al. 2016, Sec. 4 and Table 2).
///
/// A compensated program keeps the rotary angles and moves the linear axes so that the tool
/// reaches the intended table-frame point on the identified machine: xyz = inverse(identified,
/// angles, q) with q = the nominal program's table-frame target. Verification runs the
/// compensated program on the machine, records it against the nominal program (as ballbar
/// software does) and identifies again: what remains is what compensation did not remove.

#include "rotacal/ballbar/identify.hpp"
#include "rotacal/ballbar/simulate.hpp"

namespace rotacal {

/// The same session with every commanded X,Y,Z replaced by the compensated command for the
/// identified machine (location errors, and on a machine with head axes the error of
/// pivot_length + tool_length, mm; effects and pivot play no part in the command).
/// Throws InvalidArgument if the machines differ.
BallbarSession compensate_commands(const BallbarSession& nominal,
                                   const LocationErrors<double>& identified, MachineType machine,
                                   double tool_length_error = 0.0);

/// The error of pivot_length + tool_length of an identified model: minus its tool_offset_Z on
/// a machine with head axes (kinematics/effects.hpp), else 0.
double identified_tool_length_error(const BallbarMachineModel& model);

/// One location error before and after compensation.
struct CompensationRow {
  std::string name;
  std::string unit;
  double before = 0.0;  ///< identified from the uncompensated run
  double after = 0.0;   ///< identified from the compensated run
  double std_after = 0.0;
  /// 100 * (|after| - |before|) / |before| (the paper's "% Inc."; negative = reduction)
  double change_percent = 0.0;
};

struct CompensationReport {
  std::vector<CompensationRow> rows;
  BallbarIdentification before;
  BallbarIdentification after;
};

/// Measure on `truth`, identify (joint), compensate, measure again with the compensated
/// program, identify again. `commanded` is the nominal test (rows without lengths). Two noise
/// draws: options.seed for the first run, options.seed + 1 for the second.
CompensationReport verify_compensation(const BallbarSession& commanded,
                                       const BallbarMachineModel& truth,
                                       const BallbarSimulationOptions& options = {},
                                       const JointFitOptions& fit = {});

}  // namespace rotacal

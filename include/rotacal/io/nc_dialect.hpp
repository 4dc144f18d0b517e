// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The NC dialects rotacal writes programs in, and the options every NC program shares: the
/// layer below the instruments' program writers (ballbar/nc_program.hpp for the rotary-axis test,
/// circular/plan.hpp for the ISO 230-4 circles, probe/nc_program.hpp for the touch probe), so
/// that none of them includes another instrument's header.

#include <string>

namespace rotacal {

enum class NcDialect { linuxcnc, heidenhain, siemens, fanuc };

/// "linuxcnc", "heidenhain", "siemens", "fanuc".
std::string to_string(NcDialect dialect);
/// Inverse of to_string; throws InvalidArgument naming the unknown text and the known ones.
NcDialect parse_nc_dialect(const std::string& text);

struct NcProgramOptions {
  int decimals = 4;  ///< digits after the point of X Y Z (mm) and angles (deg), 0..9
  /// Tool whose length offset puts the controlled point at the tool-cup ball centre: G43 H<n>
  /// (linuxcnc), TOOL CALL <n> Z (heidenhain), T<n> D1 (siemens), G43.4 H<n> (fanuc).
  /// 0 leaves offsets to the operator (linuxcnc, siemens only; TCP dialects need a tool).
  int tool = 1;
  /// Stop (M0 / STOP) after the rapid move to the first point, to mount the ballbar.
  bool stop_to_mount = true;
  std::string program_name = "ROTACAL_BALLBAR";  ///< heidenhain BEGIN PGM name
  int program_number = 1000;                     ///< fanuc O number, 1..9999
};

/// The NC program text of `plan` in `dialect` (lines end with '\n'). The header comments give
/// the machine, L0, pivot, test order, sample count, planned duration and, for a compensated
/// plan, the identified errors used. Throws InvalidArgument for options out of range or a
/// plan without samples.

}  // namespace rotacal

// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Thermal sessions (../shared/spec/formats.md, "Thermal test of a rotary axis"): a probe or
/// R-test file read by its own strict reader, and its `epoch` column and `# duty.N:` lines read
/// here, refused by file and line where they break the spec.

#include <istream>
#include <string>
#include <vector>

#include "rotacal/io/probe_file.hpp"
#include "rotacal/session/thermal_test.hpp"

namespace rotacal {

/// Largest |speed| of a duty entry, rev/min (beyond: not a machine tool's rotary axis).
inline constexpr double kMaxDutySpeedRpm = 1.0e5;

/// A probe or R-test session with its thermal test.
struct ThermalSession {
  InstrumentSession session;
  ThermalTest thermal;                ///< empty duty: no heat input (gains unobservable)
  std::vector<std::string> warnings;  ///< the session's own, then the thermal test's
};

/// Read a thermal probe or R-test session; throws ParseError (file, line, column, what) for:
/// `# duty.N:` lines without an `epoch` column, N not consecutive from 1, a TIME negative or
/// not strictly increasing, an axis the machine lacks, a speed not a number or beyond 1e5
/// rev/min; an epoch that is not an integer >= 1 or that decreases. A ballbar session is
/// refused (InvalidArgument). A duty entry before the first row is kept with a warning: the
/// lag state starts at 0 at the first row whatever turned before it.
ThermalSession read_thermal_session(const std::string& path);

/// The duty of a prediction (`rotacal predict --duty`) for `machine`: a file of `# duty.N: TIME,
/// AXIS=SPEED, ...` lines (formats.md; other `# key: value` lines and blank lines are kept out,
/// any other line refused by line), its clock starting cold at 0 s with no epochs; or a thermal
/// session, whose duty and epochs (the axes held) are the test's, its lag state 0 at its first
/// row. ParseError (file, line) as read_thermal_session; InvalidArgument for a file without duty
/// lines or a session of another machine.
ThermalTest read_duty_file(const std::string& path, MachineType machine);

/// True when the file has an `epoch` column or `# duty.N:` lines (a cheap look at its head).
bool is_thermal_session(const std::string& path);

}  // namespace rotacal

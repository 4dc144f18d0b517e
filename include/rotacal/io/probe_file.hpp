// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// `rotacal-probe/1` files (../shared/spec/formats.md, "Touch-probe session"): a strict reader
/// whose errors name file, line, column and what is wrong, and a writer whose output reads back
/// bit-identical (shortest round-trip decimal for every double), as io/ballbar_file.hpp does
/// for the other two formats.

#include <istream>
#include <string>
#include <variant>

#include "rotacal/io/ballbar_file.hpp"
#include "rotacal/session/probe_session.hpp"

namespace rotacal {

/// Largest stylus and sphere diameters a file may hold, mm (beyond: wrong units).
inline constexpr double kMaxProbeDiameterMm = 1.0e3;
/// Largest | |n| - 1 | of an approach direction that is normalised on reading (formats.md).
inline constexpr double kMaxDirectionNormError = 1.0e-4;

/// Read a touch-probe session; throws ParseError (file, line, column, what) or IoError.
/// Refused besides the common rules (missing column or metadata, non-numeric value, NaN,
/// decreasing time, unknown machine): a direction whose norm is off 1 by more than 1e-4, a
/// sphere diameter <= 0, a stylus diameter < 0, and a pose whose touches are not at one
/// rotary position (a pose is held at rest). Directions are normalised.
ProbeSession read_probe(const std::string& path);
/// Parse a touch-probe session from a stream; `name` is used in error messages.
ProbeSession parse_probe(std::istream& in, const std::string& name);
/// The file text of a session; throws InvalidArgument for a session that would not read back.
std::string format_probe(const ProbeSession& session);
/// Write by the output rule of io/output_file.hpp; throws IoError naming the path.
void write_probe(const ProbeSession& session, const std::string& path);

/// Any of the three sessions, chosen by the file's `# format:` line (read_session for the
/// ballbar and R-test formats).
using InstrumentSession = std::variant<BallbarSession, RtestSession, ProbeSession>;
InstrumentSession read_instrument_session(const std::string& path);

}  // namespace rotacal

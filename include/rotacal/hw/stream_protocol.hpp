// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// What the ballbar stream and the R-test probe stream share (docs/protocols.md): the host's
/// command lines (StreamCommand), the framed text replies, and the samples' sequence numbers.
///
///   host -> device   "START\n"  "STOP\n"  "ZERO\n" (ballbar only)  "ID?\n"  "RATE <hz>\n"
///   device -> host   text frame (type 0x02): "OK START", "OK STOP", "OK ZERO", "OK RATE 1000",
///                    "ID <model> <firmware>", "ERR <what>", "END" (stream finished)

#include <cstdint>
#include <optional>
#include <string>

#include "rotacal/hw/frame.hpp"

namespace rotacal::hw {

inline constexpr std::uint8_t kTextFrame = 0x02;

Bytes encode_text(const std::string& text);
/// The text of a text frame; nullopt for other frames or non-printable content.
std::optional<std::string> decode_text(const Frame& f);

/// Frames lost between two consecutive sequence numbers (0 if `next` follows `prev`).
inline int sequence_gap(std::uint16_t prev, std::uint16_t next) {
  return static_cast<std::uint16_t>(next - prev - 1);
}

/// The commands of both streams. `zero` is the ballbar's; a probe stream answers it with ERR.
enum class StreamCommand { start, stop, zero, identify, rate };

/// A parsed host command line (device side).
struct StreamCommandLine {
  StreamCommand command = StreamCommand::start;
  double rate_hz = 0.0;  ///< for `rate`
};

/// The line the host sends (with its newline). `rate_hz` only for StreamCommand::rate.
std::string format_command(StreamCommand c, double rate_hz = 0.0);
/// Parse one command line (without the newline, surrounding blanks ignored); nullopt if it is
/// not a command of this protocol.
std::optional<StreamCommandLine> parse_command(const std::string& line);

}  // namespace rotacal::hw

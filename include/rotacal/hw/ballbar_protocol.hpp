#pragma once
/// \file
/// The ballbar transducer protocol (docs/protocols.md): host commands are ASCII lines, the
/// transducer answers with framed text replies and streams framed samples (frame.hpp) at up
/// to 1 kHz. Pure encode/decode functions; the I/O lives in recorder.hpp and virtual_ballbar.hpp.
///
///   host -> device   "START\n"  "STOP\n"  "ZERO\n"  "ID?\n"  "RATE <hz>\n"
///   device -> host   text frame (type 0x02): "OK START", "OK STOP", "OK ZERO", "OK RATE 1000",
///                    "ID <model> <firmware>", "ERR <what>", "END" (stream finished)
///                    sample frame (type 0x01, 11 bytes): seq u16 | t_us u32 | displacement_nm
///                    i32 | status u8 (bit 0: over range)

#include <cstdint>
#include <optional>
#include <string>

#include "rotacal/hw/frame.hpp"

namespace rotacal::hw {

inline constexpr std::uint8_t kTextFrame = 0x02;
inline constexpr std::uint8_t kBallbarSampleFrame = 0x01;
inline constexpr std::uint8_t kStatusOverRange = 0x01;

/// One transducer sample: displacement from the length at which it was zeroed (in the
/// calibrator, at L0), on the transducer's own clock.
struct BallbarFrame {
  std::uint16_t seq = 0;           ///< increments by one per sample, wraps at 65536
  std::uint32_t t_us = 0;          ///< µs since START, wraps at 2^32
  std::int32_t displacement_nm = 0;
  std::uint8_t status = 0;
};

Bytes encode_ballbar_sample(const BallbarFrame& f);
/// The sample in a frame; nullopt if the frame is not a well-formed sample frame.
std::optional<BallbarFrame> decode_ballbar_sample(const Frame& f);

Bytes encode_text(const std::string& text);
/// The text of a text frame; nullopt for other frames or non-printable content.
std::optional<std::string> decode_text(const Frame& f);

/// Frames lost between two consecutive sequence numbers (0 if `next` follows `prev`).
inline int sequence_gap(std::uint16_t prev, std::uint16_t next) {
  return static_cast<std::uint16_t>(next - prev - 1);
}

enum class BallbarCommand { start, stop, zero, identify, rate };

/// A parsed host command line (device side).
struct BallbarCommandLine {
  BallbarCommand command = BallbarCommand::start;
  double rate_hz = 0.0;  ///< for `rate`
};

/// The line the host sends (with its newline). `rate_hz` only for BallbarCommand::rate.
std::string format_command(BallbarCommand c, double rate_hz = 0.0);
/// Parse one command line (without the newline, surrounding blanks ignored); nullopt if it is
/// not a command of this protocol.
std::optional<BallbarCommandLine> parse_command(const std::string& line);

}  // namespace rotacal::hw

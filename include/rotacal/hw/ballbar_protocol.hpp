// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The ballbar transducer protocol (docs/protocols.md): the host's commands, the text replies
/// and the sequence numbers are the stream protocol's (stream_protocol.hpp); the transducer
/// streams framed samples (frame.hpp) at up to 1 kHz. Pure encode/decode functions; the I/O
/// lives in recorder.hpp and virtual_instrument.hpp.
///
///   sample frame (type 0x01, 11 bytes): seq u16 | t_us u32 | displacement_nm i32 | status u8
///   (bit 0: over range)

#include <cstdint>
#include <optional>
#include <string>

#include "rotacal/hw/frame.hpp"
#include "rotacal/hw/stream_protocol.hpp"

namespace rotacal::hw {

inline constexpr std::uint8_t kBallbarSampleFrame = 0x01;
inline constexpr std::uint8_t kStatusOverRange = 0x01;

/// One transducer sample: displacement from the length at which it was zeroed (in the
/// calibrator, at L0), on the transducer's own clock.
struct BallbarFrame {
  std::uint16_t seq = 0;   ///< increments by one per sample, wraps at 65536
  std::uint32_t t_us = 0;  ///< µs since START, wraps at 2^32
  std::int32_t displacement_nm = 0;
  std::uint8_t status = 0;
};

Bytes encode_ballbar_sample(const BallbarFrame& f);
/// The sample in a frame; nullopt if the frame is not a well-formed sample frame.
std::optional<BallbarFrame> decode_ballbar_sample(const Frame& f);

}  // namespace rotacal::hw

// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Binary framing shared by the ballbar stream and the probe stream (docs/protocols.md):
///
///     0xAA 0x55 | type u8 | len u8 | payload[len] | crc16 u16 little-endian
///
/// CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF, no reflection) over type, len and payload.
/// The functions here are pure: bytes in, frames out, no I/O and no state, so they can be
/// fuzzed (fuzz/) and reused by the device simulator and the recorder alike.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace rotacal::hw {

using Bytes = std::vector<std::uint8_t>;

inline constexpr std::uint8_t kSync0 = 0xAA;
inline constexpr std::uint8_t kSync1 = 0x55;
/// Longest payload a frame may declare. A larger `len` is not a frame start (it is garbage),
/// so a corrupted length byte cannot stall the decoder waiting for bytes that never come.
inline constexpr std::size_t kMaxPayload = 64;
/// Bytes around the payload: sync (2), type, len, crc (2).
inline constexpr std::size_t kFrameOverhead = 6;

/// CRC-16/CCITT-FALSE; "123456789" gives 0x29B1.
std::uint16_t crc16_ccitt(const std::uint8_t* data, std::size_t n, std::uint16_t crc = 0xFFFF);

/// One complete frame. Throws InvalidArgument if the payload is longer than kMaxPayload.
Bytes encode_frame(std::uint8_t type, const Bytes& payload);

struct Frame {
  std::uint8_t type = 0;
  Bytes payload;
};

/// What scan_frames found in a buffer.
struct FrameScan {
  std::vector<Frame> frames;  ///< valid frames, in order
  std::size_t consumed = 0;   ///< bytes fully processed; keep data[consumed..n) for the next read
  std::size_t garbage_bytes = 0;  ///< bytes skipped while looking for a frame start
  std::size_t crc_errors = 0;     ///< complete frames whose checksum failed (dropped, resynced)
};

/// Every complete frame in data[0..n). An incomplete frame at the end is left unconsumed;
/// a frame that fails its checksum is counted and scanning resumes one byte after its start.
FrameScan scan_frames(const std::uint8_t* data, std::size_t n);

/// Little-endian field access for payloads.
void put_u16(Bytes& b, std::uint16_t v);
void put_u32(Bytes& b, std::uint32_t v);
std::uint16_t get_u16(const std::uint8_t* p);
std::uint32_t get_u32(const std::uint8_t* p);

}  // namespace rotacal::hw

// SPDX-License-Identifier: BSD-3-Clause
// Binary framing: CRC-16, frame encode and the resynchronising scanner (frame.hpp).
#include "rotacal/hw/frame.hpp"

#include "rotacal/core/error.hpp"

namespace rotacal::hw {

std::uint16_t crc16_ccitt(const std::uint8_t* data, std::size_t n, std::uint16_t crc) {
  for (std::size_t i = 0; i < n; ++i) {
    crc = static_cast<std::uint16_t>(crc ^ (static_cast<std::uint16_t>(data[i]) << 8));
    for (int bit = 0; bit < 8; ++bit)
      crc = static_cast<std::uint16_t>((crc & 0x8000) ? (crc << 1) ^ 0x1021 : (crc << 1));
  }
  return crc;
}

void put_u16(Bytes& b, std::uint16_t v) {
  b.push_back(static_cast<std::uint8_t>(v & 0xFF));
  b.push_back(static_cast<std::uint8_t>(v >> 8));
}

void put_u32(Bytes& b, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b.push_back(static_cast<std::uint8_t>((v >> (8 * i)) & 0xFF));
}

std::uint16_t get_u16(const std::uint8_t* p) {
  return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
}

std::uint32_t get_u32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}

Bytes encode_frame(std::uint8_t type, const Bytes& payload) {
  if (payload.size() > kMaxPayload)
    throw InvalidArgument("encode_frame: payload of " + std::to_string(payload.size()) +
                          " bytes exceeds the maximum of " + std::to_string(kMaxPayload));
  Bytes out{kSync0, kSync1, type, static_cast<std::uint8_t>(payload.size())};
  out.insert(out.end(), payload.begin(), payload.end());
  put_u16(out, crc16_ccitt(out.data() + 2, out.size() - 2));
  return out;
}

FrameScan scan_frames(const std::uint8_t* data, std::size_t n) {
  FrameScan scan;
  std::size_t i = 0;
  while (i < n) {
    if (data[i] != kSync0) {
      ++i;
      ++scan.garbage_bytes;
      continue;
    }
    if (i + 1 >= n) break;  // lone sync byte at the end: may be a frame start
    if (data[i + 1] != kSync1) {
      ++i;
      ++scan.garbage_bytes;
      continue;
    }
    if (i + 4 > n) break;  // header incomplete
    const std::size_t len = data[i + 3];
    if (len > kMaxPayload) {
      ++i;
      ++scan.garbage_bytes;
      continue;
    }
    const std::size_t total = len + kFrameOverhead;
    if (i + total > n) break;  // frame incomplete: wait for more bytes
    const std::uint16_t crc = crc16_ccitt(data + i + 2, len + 2);
    if (crc != get_u16(data + i + 4 + len)) {
      ++scan.crc_errors;
      ++i;  // resync one byte on: the length byte itself may have been corrupted
      continue;
    }
    scan.frames.push_back({data[i + 2], Bytes(data + i + 4, data + i + 4 + len)});
    i += total;
  }
  scan.consumed = i;
  return scan;
}

}  // namespace rotacal::hw

// SPDX-License-Identifier: BSD-3-Clause
// Ballbar sample frames: encode and decode (ballbar_protocol.hpp).
#include "rotacal/hw/ballbar_protocol.hpp"

namespace rotacal::hw {

namespace {
constexpr std::size_t kSamplePayload = 11;
}  // namespace

Bytes encode_ballbar_sample(const BallbarFrame& f) {
  Bytes p;
  p.reserve(kSamplePayload);
  put_u16(p, f.seq);
  put_u32(p, f.t_us);
  put_u32(p, static_cast<std::uint32_t>(f.displacement_nm));
  p.push_back(f.status);
  return encode_frame(kBallbarSampleFrame, p);
}

std::optional<BallbarFrame> decode_ballbar_sample(const Frame& f) {
  if (f.type != kBallbarSampleFrame || f.payload.size() != kSamplePayload) return std::nullopt;
  const std::uint8_t* p = f.payload.data();
  BallbarFrame s;
  s.seq = get_u16(p);
  s.t_us = get_u32(p + 2);
  s.displacement_nm = static_cast<std::int32_t>(get_u32(p + 6));
  s.status = p[10];
  return s;
}

}  // namespace rotacal::hw

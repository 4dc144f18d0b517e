// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer target: the binary frame decoder and the sample decoders behind it must accept any
// bytes without crashing, reading out of bounds or looping, and must account for every byte.
#include <cstdlib>

#include "rotacal/hw/ballbar_protocol.hpp"
#include "rotacal/hw/probe_protocol.hpp"

using namespace rotacal::hw;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const FrameScan s = scan_frames(data, size);
  if (s.consumed > size) std::abort();
  std::size_t framed = 0;
  for (const Frame& f : s.frames) {
    if (f.payload.size() > kMaxPayload) std::abort();
    framed += f.payload.size() + kFrameOverhead;
    if (const auto b = decode_ballbar_sample(f)) {
      // A decoded sample re-encodes to the frame it came from.
      const Bytes again = encode_ballbar_sample(*b);
      const FrameScan r = scan_frames(again.data(), again.size());
      if (r.frames.size() != 1 || r.frames[0].payload != f.payload) std::abort();
    }
    (void)decode_probe_sample(f);
    (void)decode_text(f);
  }
  if (framed + s.garbage_bytes > s.consumed) std::abort();
  return 0;
}

// SPDX-License-Identifier: BSD-3-Clause
// Binary framing: CRC check value, round trips, resynchronisation after garbage and corruption.
#include <catch2/catch.hpp>
#include <cstring>

#include "rotacal/core/error.hpp"
#include "rotacal/hw/frame.hpp"

using namespace rotacal;
using namespace rotacal::hw;

TEST_CASE("CRC-16/CCITT-FALSE check value", "[hw]") {
  const char* check = "123456789";  // the catalogue check value of this CRC is 0x29B1
  CHECK(crc16_ccitt(reinterpret_cast<const std::uint8_t*>(check), 9) == 0x29B1);
}

TEST_CASE("a frame round-trips and its layout is as documented", "[hw]") {
  const Bytes f = encode_frame(0x07, {1, 2, 3});
  REQUIRE(f.size() == 3 + kFrameOverhead);
  CHECK(f[0] == 0xAA);
  CHECK(f[1] == 0x55);
  CHECK(f[2] == 0x07);
  CHECK(f[3] == 3);
  const FrameScan s = scan_frames(f.data(), f.size());
  REQUIRE(s.frames.size() == 1);
  CHECK(s.frames[0].type == 0x07);
  CHECK(s.frames[0].payload == Bytes{1, 2, 3});
  CHECK(s.consumed == f.size());
  CHECK(s.garbage_bytes == 0);
  CHECK_THROWS_AS(encode_frame(1, Bytes(kMaxPayload + 1, 0)), InvalidArgument);
}

TEST_CASE("scan_frames: garbage, split frames, checksum errors", "[hw]") {
  const Bytes a = encode_frame(1, {10, 20});
  const Bytes b = encode_frame(2, {30});
  Bytes stream{0x00, 0xAA, 0x13};  // 3 bytes of noise, one of them a false sync byte
  stream.insert(stream.end(), a.begin(), a.end());
  Bytes bad = b;
  bad[4] ^= 0x01;  // payload bit flipped
  stream.insert(stream.end(), bad.begin(), bad.end());
  stream.insert(stream.end(), b.begin(), b.end());

  SECTION("all at once") {
    const FrameScan s = scan_frames(stream.data(), stream.size());
    REQUIRE(s.frames.size() == 2);
    CHECK(s.frames[0].payload == Bytes{10, 20});
    CHECK(s.frames[1].payload == Bytes{30});
    CHECK(s.crc_errors == 1);
    CHECK(s.garbage_bytes == 3 + bad.size() - 1);  // noise, then the bad frame after its first byte
    CHECK(s.consumed == stream.size());
  }
  SECTION("byte by byte, as the slowest link would deliver it") {
    Bytes pending;
    std::vector<Frame> frames;
    std::size_t crc = 0;
    for (std::uint8_t byte : stream) {
      pending.push_back(byte);
      FrameScan s = scan_frames(pending.data(), pending.size());
      pending.erase(pending.begin(), pending.begin() + static_cast<long>(s.consumed));
      frames.insert(frames.end(), s.frames.begin(), s.frames.end());
      crc += s.crc_errors;
    }
    REQUIRE(frames.size() == 2);
    CHECK(frames[1].payload == Bytes{30});
    CHECK(crc == 1);
    CHECK(pending.empty());
  }
  SECTION("a frame cut short waits for the rest") {
    const FrameScan s = scan_frames(a.data(), a.size() - 1);
    CHECK(s.frames.empty());
    CHECK(s.consumed == 0);
    CHECK(s.garbage_bytes == 0);
  }
}

TEST_CASE("a corrupted length byte cannot stall the decoder", "[hw]") {
  Bytes stream{0xAA, 0x55, 0x01, 0xFF};  // declares 255 bytes: not a frame start
  const Bytes a = encode_frame(1, {42});
  stream.insert(stream.end(), a.begin(), a.end());
  const FrameScan s = scan_frames(stream.data(), stream.size());
  REQUIRE(s.frames.size() == 1);
  CHECK(s.frames[0].payload == Bytes{42});
  CHECK(s.garbage_bytes == 4);
}

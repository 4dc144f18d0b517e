// SPDX-License-Identifier: BSD-3-Clause
// Ballbar sample frames: encode/decode round trip, refusal of other frames.
#include <catch2/catch.hpp>

#include "rotacal/hw/ballbar_protocol.hpp"

using namespace rotacal::hw;

TEST_CASE("ballbar sample frames round-trip, negative displacements included", "[hw]") {
  for (const BallbarFrame f :
       {BallbarFrame{0, 0, 0, 0}, BallbarFrame{65535, 4294967295u, -123456789, 1},
        BallbarFrame{17, 1000, 987654, 0}}) {
    const Bytes bytes = encode_ballbar_sample(f);
    CHECK(bytes.size() == 17);  // 11-byte payload + framing, as docs/protocols.md says
    const FrameScan s = scan_frames(bytes.data(), bytes.size());
    REQUIRE(s.frames.size() == 1);
    const auto d = decode_ballbar_sample(s.frames[0]);
    REQUIRE(d);
    CHECK(d->seq == f.seq);
    CHECK(d->t_us == f.t_us);
    CHECK(d->displacement_nm == f.displacement_nm);
    CHECK(d->status == f.status);
  }
}

TEST_CASE("frames of another type or size are not samples", "[hw]") {
  CHECK_FALSE(decode_ballbar_sample(Frame{kTextFrame, Bytes(11, 0)}));
  CHECK_FALSE(decode_ballbar_sample(Frame{kBallbarSampleFrame, Bytes(10, 0)}));
  CHECK_FALSE(decode_text(Frame{kBallbarSampleFrame, {'E'}}));
}

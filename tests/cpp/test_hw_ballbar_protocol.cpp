#include <catch2/catch.hpp>

#include "rotacal/core/error.hpp"
#include "rotacal/hw/ballbar_protocol.hpp"

using namespace rotacal;
using namespace rotacal::hw;

TEST_CASE("ballbar sample frames round-trip, negative displacements included", "[hw]") {
  for (const BallbarFrame f : {BallbarFrame{0, 0, 0, 0}, BallbarFrame{65535, 4294967295u, -123456789, 1},
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
  CHECK(decode_text(Frame{kTextFrame, {'E', 'N', 'D'}}) == std::string("END"));
  CHECK_FALSE(decode_text(Frame{kTextFrame, {'E', 0x01}}));
  CHECK_FALSE(decode_text(Frame{kBallbarSampleFrame, {'E'}}));
}

TEST_CASE("sequence gaps across the 16-bit wrap", "[hw]") {
  CHECK(sequence_gap(5, 6) == 0);
  CHECK(sequence_gap(5, 9) == 3);
  CHECK(sequence_gap(65535, 0) == 0);
  CHECK(sequence_gap(65534, 1) == 2);
}

TEST_CASE("host commands: format and parse agree; bad lines are refused", "[hw]") {
  for (BallbarCommand c : {BallbarCommand::start, BallbarCommand::stop, BallbarCommand::zero, BallbarCommand::identify}) {
    const auto p = parse_command(format_command(c));
    REQUIRE(p);
    CHECK(p->command == c);
  }
  const auto r = parse_command(format_command(BallbarCommand::rate, 500));
  REQUIRE(r);
  CHECK(r->rate_hz == 500);
  CHECK_FALSE(parse_command("RATE 0"));
  CHECK_FALSE(parse_command("RATE 1001"));
  CHECK_FALSE(parse_command("RATE 10x"));
  CHECK_FALSE(parse_command("start"));
  CHECK_THROWS_AS(format_command(BallbarCommand::rate, 2000), InvalidArgument);
  CHECK_THROWS_AS(format_command(BallbarCommand::rate, 12.5), InvalidArgument);
}

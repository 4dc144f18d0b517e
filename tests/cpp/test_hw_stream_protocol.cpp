// SPDX-License-Identifier: BSD-3-Clause
// The stream protocol both instruments share: text frames, sequence gaps, host commands.
#include <catch2/catch.hpp>

#include "rotacal/core/error.hpp"
#include "rotacal/hw/stream_protocol.hpp"

using namespace rotacal;
using namespace rotacal::hw;

TEST_CASE("text frames: printable text only, other frame types are not text", "[hw]") {
  CHECK(decode_text(Frame{kTextFrame, {'E', 'N', 'D'}}) == std::string("END"));
  CHECK_FALSE(decode_text(Frame{kTextFrame, {'E', 0x01}}));
  const Bytes bytes = encode_text("OK START");
  const FrameScan s = scan_frames(bytes.data(), bytes.size());
  REQUIRE(s.frames.size() == 1);
  CHECK(decode_text(s.frames[0]) == std::string("OK START"));
}

TEST_CASE("sequence gaps across the 16-bit wrap", "[hw]") {
  CHECK(sequence_gap(5, 6) == 0);
  CHECK(sequence_gap(5, 9) == 3);
  CHECK(sequence_gap(65535, 0) == 0);
  CHECK(sequence_gap(65534, 1) == 2);
}

TEST_CASE("host commands: format and parse agree; bad lines are refused", "[hw]") {
  for (StreamCommand c :
       {StreamCommand::start, StreamCommand::stop, StreamCommand::zero, StreamCommand::identify}) {
    const auto p = parse_command(format_command(c));
    REQUIRE(p);
    CHECK(p->command == c);
  }
  const auto r = parse_command(format_command(StreamCommand::rate, 500));
  REQUIRE(r);
  CHECK(r->rate_hz == 500);
  CHECK_FALSE(parse_command("RATE 0"));
  CHECK_FALSE(parse_command("RATE 1001"));
  CHECK_FALSE(parse_command("RATE 10x"));
  CHECK_FALSE(parse_command("start"));
  CHECK_THROWS_AS(format_command(StreamCommand::rate, 2000), InvalidArgument);
  CHECK_THROWS_AS(format_command(StreamCommand::rate, 12.5), InvalidArgument);
}

// SPDX-License-Identifier: BSD-3-Clause
// ASCII probe dialects and probe stream frames: parse/format agreement, refusals.
#include <catch2/catch.hpp>

#include "rotacal/core/error.hpp"
#include "rotacal/hw/probe_protocol.hpp"

using namespace rotacal;
using namespace rotacal::hw;

namespace {
LineScan lines_of(const std::string& s) {
  return split_lines(reinterpret_cast<const std::uint8_t*>(s.data()), s.size());
}
}  // namespace

TEST_CASE("split_lines: CR, LF, CRLF, partial lines and garbage", "[hw]") {
  const LineScan s = lines_of("+012.3456\r\nM0,+1\r\x01junk\npart");
  REQUIRE(s.lines.size() == 3);
  CHECK(s.lines[0] == "+012.3456");
  CHECK(s.lines[1] == "M0,+1");
  CHECK(s.lines[2] == "junk");
  CHECK(s.garbage_bytes == 1);
  CHECK(s.consumed == std::string("+012.3456\r\nM0,+1\r\x01junk\n").size());  // "part" waits
  const LineScan overlong = lines_of(std::string(200, 'x'));
  CHECK(overlong.lines.empty());
  CHECK(overlong.garbage_bytes == 200);
  CHECK(overlong.consumed == 200);
}

TEST_CASE("sylvac-style replies", "[hw]") {
  CHECK(sylvac_request(2) == "?2\r");
  CHECK(parse_sylvac_request("?3") == 3);
  CHECK_FALSE(parse_sylvac_request("?4"));
  CHECK_THROWS_AS(sylvac_request(0), InvalidArgument);
  const auto v = parse_sylvac_reply("+012.3456");
  REQUIRE(v);
  CHECK(v->ok());
  CHECK(v->mm == Approx(12.3456));
  CHECK(parse_sylvac_reply("-000.0012")->mm == Approx(-0.0012));
  CHECK(parse_sylvac_reply("Err01")->kind == GaugeValue::Kind::over_range);
  CHECK(parse_sylvac_reply("Err02")->kind == GaugeValue::Kind::error);
  CHECK(parse_sylvac_reply("Err02")->code == 2);
  CHECK(parse_sylvac_reply("?")->kind == GaugeValue::Kind::error);
  for (const char* bad :
       {"", "12.3", "+", "+1.2.3", "+12a", "Err1", "+nan", "+0444444412", "+1.1234567"})
    CHECK_FALSE(parse_sylvac_reply(bad));  // the 10-digit value: found by fuzz_probe_lines
  // format then parse gives the value back to the reply's 0.1 um resolution
  const std::string line = format_sylvac_reply({GaugeValue::Kind::value, -1.23456, 0});
  CHECK(line == "-001.2346\r");
  CHECK(parse_sylvac_reply(line.substr(0, line.size() - 1))->mm == Approx(-1.2346));
}

TEST_CASE("keyence-style replies", "[hw]") {
  CHECK(keyence_request(0) == "M0\r");
  CHECK(parse_keyence_request("M2") == 2);
  CHECK_FALSE(parse_keyence_request("M4"));
  const auto all = parse_keyence_reply("M0,+01.2345,-00.1234,+FFFFFFF");
  REQUIRE(all);
  CHECK(all->channel == 0);
  REQUIRE(all->values.size() == 3);
  CHECK(all->values[0].mm == Approx(1.2345));
  CHECK(all->values[1].mm == Approx(-0.1234));
  CHECK(all->values[2].kind == GaugeValue::Kind::over_range);
  CHECK(parse_keyence_reply("M1,-FFFFFFF")->values[0].kind == GaugeValue::Kind::under_range);
  const auto er = parse_keyence_reply("ER,M1,02");
  REQUIRE(er);
  CHECK(er->values[0].kind == GaugeValue::Kind::error);
  CHECK(er->values[0].code == 2);
  for (const char* bad : {"M0,+1.0", "M1,+1,+2", "M5,+1", "ER,M1,2", "ER,X1,02", "M1,1.0", "M1"})
    CHECK_FALSE(parse_keyence_reply(bad));
  const KeyenceReply r{0,
                       {{GaugeValue::Kind::value, 0.5, 0},
                        {GaugeValue::Kind::under_range, 0, 0},
                        {GaugeValue::Kind::value, -0.00004, 0}}};
  CHECK(format_keyence_reply(r) == "M0,+00.5000,-FFFFFFF,-00.0000\r");
}

TEST_CASE("probe stream frames round-trip", "[hw]") {
  const ProbeFrame f{300, 123456, {-5, 2000000, -1999999}, 0x04};
  const Bytes b = encode_probe_sample(f);
  const FrameScan s = scan_frames(b.data(), b.size());
  REQUIRE(s.frames.size() == 1);
  const auto d = decode_probe_sample(s.frames[0]);
  REQUIRE(d);
  CHECK(d->seq == 300);
  CHECK(d->t_us == 123456);
  CHECK(d->nm == f.nm);
  CHECK(d->status == 0x04);
  CHECK(parse_probe_mode("stream") == ProbeMode::stream);
  CHECK_THROWS_AS(parse_probe_mode("serial"), InvalidArgument);
}

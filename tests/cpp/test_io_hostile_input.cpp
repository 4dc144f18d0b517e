// SPDX-License-Identifier: BSD-3-Clause
// Session readers against hostile and careless input: bounded memory and messages, UTF-8,
// BOM, directories, magnitudes no machine has, duplicated rows (issue 17 items 2, 3, 6, 11).
#include <sys/stat.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <fstream>
#include <sstream>

#include "rotacal/core/error.hpp"
#include "rotacal/io/ballbar_file.hpp"

using namespace rotacal;

namespace {

const std::string kBallbarHead =
    "# format: rotacal-ballbar/1\n# machine: AC-trt\n# units: mm, deg, s\n"
    "# ballbar_length: 100.0000\n# pivot: 120.0000, 0.0000, 60.0000\n"
    "test,time,X,Y,Z,A,C,length\n";
const std::string kRow =
    "sphere_xy,0.000,220.000000,0.000000,60.000000,0.000000,0.000000,99.9904419\n";
const std::string kRow2 =
    "sphere_xy,0.100,219.000000,1.000000,60.000000,0.000000,1.000000,99.9904419\n";
const std::string kRtestHead =
    "# format: rotacal-rtest/1\n# machine: BC-trt\n# units: mm, deg, s\n"
    "# nest.1: 100.0000, 0.0000, 60.0000\nsetup,time,B,C,X,Y,Z,dx,dy,dz\n";
const std::string kRtestRow =
    "1,0.0,-90.0000,0.0000,-60.000000,0.000000,100.000000,0.0058340,-0.0301318,-0.0129457\n";

ParseError refusal(const std::string& text, bool rtest = false) {
  std::istringstream in(text);
  try {
    if (rtest)
      parse_rtest(in, "bad.csv");
    else
      parse_ballbar(in, "bad.csv");
  } catch (const ParseError& e) {
    return e;
  }
  FAIL("accepted:\n" << text.substr(0, 300));
  throw;
}

// Replaces field `k` (0-based) of a CSV row.
std::string with_field(const std::string& row, int k, const std::string& value) {
  std::vector<std::string> f;
  std::stringstream ss(row.substr(0, row.size() - 1));
  for (std::string x; std::getline(ss, x, ',');) f.push_back(x);
  f[static_cast<std::size_t>(k)] = value;
  std::string out;
  for (std::size_t i = 0; i < f.size(); ++i) out += (i ? "," : "") + f[i];
  return out + "\n";
}

}  // namespace

TEST_CASE("/dev/zero and a file without line ends are refused after one bounded line") {
  try {
    (void)read_session("/dev/zero");
    FAIL("/dev/zero accepted");
  } catch (const ParseError& e) {
    CHECK_THAT(e.what(),
               Catch::Contains("/dev/zero") && Catch::Contains("longer than 65536 bytes"));
    CHECK(std::string(e.what()).size() < 250);
  }
  // 20 MB on one line (a CR-only file of 200 MB behaves the same: stopped at 64 kB).
  std::string big(20u << 20, 'a');
  big.replace(0, 10, "# format: ");
  const ParseError e = refusal(big);
  CHECK(e.line() == 1);
  CHECK(std::string(e.what()).size() < 250);
  std::string cr_only = kBallbarHead + kRow;
  for (char& c : cr_only)
    if (c == '\n') c = '\r';
  const ParseError cr = refusal(cr_only);
  CHECK_THAT(cr.what(), Catch::Contains("carriage return"));
  CHECK(std::string(cr.what()).size() < 250);
}

TEST_CASE("CRLF line ends are read; bytes that are not UTF-8 name line and column") {
  std::string crlf = kBallbarHead + kRow;
  std::string t;
  for (char c : crlf) t += c == '\n' ? std::string("\r\n") : std::string(1, c);
  std::istringstream in(t);
  CHECK(parse_ballbar(in, "crlf.csv").samples.size() == 1);

  const ParseError bad = refusal(kBallbarHead + "sphere_xy,0.000,22\xff.0,0,60,0,0,100\n");
  CHECK(bad.line() == 7);
  CHECK(bad.column() == 19);
  CHECK_THAT(bad.what(), Catch::Contains("0xFF is not UTF-8"));
  CHECK(refusal(kBallbarHead + "sph\xc3\x28re,0,220,0,60,0,0,100\n").column() ==
        4);  // broken 2-byte
  CHECK(refusal(kBallbarHead + "\xed\xa0\x80,0,220,0,60,0,0,100\n").column() == 1);  // a surrogate
  CHECK(refusal(kBallbarHead + "s\x01,0,220,0,60,0,0,100\n").column() == 2);         // control char
  // A UTF-16 file: a NUL on its first line.
  CHECK_THAT(refusal(std::string("\xff\xfe#\0 \0f\0", 8)).what(),
             Catch::Contains("line 1") || Catch::Contains(":1:"));
  // Valid non-ASCII labels are fine.
  std::istringstream ok(kBallbarHead + with_field(kRow, 0, "r\xc3\xa9sum\xc3\xa9_\xe2\x88\x86"));
  CHECK(parse_ballbar(ok, "ok.csv").samples[0].test == "r\xc3\xa9sum\xc3\xa9_\xe2\x88\x86");
}

TEST_CASE("a UTF-8 byte-order mark is refused by name") {
  const ParseError e = refusal("\xEF\xBB\xBF" + kBallbarHead + kRow);
  CHECK(e.line() == 1);
  CHECK_THAT(e.what(), Catch::Contains("byte-order mark"));
}

TEST_CASE("a directory as input is a file-system error, not an empty file") {
  char tmpl[] = "/tmp/rotacal-hostile-XXXXXX";
  REQUIRE(::mkdtemp(tmpl) != nullptr);
  CHECK_THROWS_AS(read_session(tmpl), IoError);
  CHECK_THROWS_WITH(read_ballbar(tmpl), Catch::Contains("is a directory"));
  CHECK_THROWS_AS(read_rtest(tmpl), IoError);
  ::rmdir(tmpl);
  CHECK_THROWS_AS(read_session(std::string("f.csv\0junk", 10)), IoError);
}

TEST_CASE("magnitudes no machine has are refused where they are read, naming the column") {
  struct Case {
    int field;
    const char* value;
    int column_of_field;
  };
  // length 1e308, X 1e160, A 1e308, time 1e300, length 4e-320 (denormal), C 1e300
  for (const auto& [field, value, col] :
       {Case{7, "1e308", 0}, Case{2, "1e160", 0}, Case{5, "1e308", 0}, Case{1, "1e300", 0},
        Case{7, "4e-320", 0}, Case{6, "1e300", 0}}) {
    (void)col;
    const ParseError e = refusal(kBallbarHead + kRow + with_field(kRow2, field, value));
    CHECK(e.line() == 8);
    CHECK(e.column() > 0);
    CHECK_THAT(e.what(), Catch::Contains("outside") || Catch::Contains("before the previous"));
  }
  const ParseError len = refusal(kBallbarHead + with_field(kRow, 7, "1e308"));
  CHECK_THAT(len.what(), Catch::Contains("length 1e308 is outside [0.001, 10000] mm"));
  CHECK_THAT(
      refusal(std::string(kBallbarHead).replace(kBallbarHead.find("100.0000"), 8, "1e6") + kRow)
          .what(),
      Catch::Contains("ballbar_length"));
  CHECK_THAT(
      refusal(std::string(kBallbarHead).replace(kBallbarHead.find("120.0000"), 8, "1e300") + kRow)
          .what(),
      Catch::Contains("pivot"));
  // R-test: dx 1e308, B 1e308.
  CHECK_THAT(refusal(kRtestHead + with_field(kRtestRow, 7, "1e308"), true).what(),
             Catch::Contains("dx 1e308"));
  CHECK_THAT(refusal(kRtestHead + with_field(kRtestRow, 2, "1e308"), true).what(),
             Catch::Contains("B 1e308"));
}

TEST_CASE("labels and values are bounded and echoed at most ~80 characters") {
  const std::string long_label(300, 'L');
  const ParseError e = refusal(kBallbarHead + with_field(kRow, 0, long_label));
  CHECK_THAT(e.what(), Catch::Contains("longer than 256 bytes"));
  CHECK(std::string(e.what()).size() < 250);
  const ParseError n = refusal(kBallbarHead + with_field(kRow, 2, std::string(5000, '9') + "x"));
  CHECK_THAT(n.what(), Catch::Contains("is not a number"));
  CHECK(std::string(n.what()).size() < 250);
  const ParseError m =
      refusal("# format: rotacal-ballbar/1\n# machine: " + std::string(10000, 'M') + "\n");
  CHECK(std::string(m.what()).size() < 250);
}

TEST_CASE("rows repeated exactly are kept and reported as a warning") {
  std::istringstream in(kBallbarHead + kRow + kRow2 + kRow2 + kRow2);
  const BallbarSession s = parse_ballbar(in, "dup.csv");
  CHECK(s.samples.size() == 4);
  REQUIRE(s.warnings.size() == 1);
  CHECK_THAT(s.warnings[0], Catch::StartsWith("2 rows repeat an earlier row") &&
                                Catch::Contains("line 9 repeats line 8"));
  std::istringstream clean(kBallbarHead + kRow + kRow2);
  CHECK(parse_ballbar(clean, "ok.csv").warnings.empty());
  std::istringstream rt(kRtestHead + kRtestRow + kRtestRow);
  CHECK(parse_rtest(rt, "dup.csv").warnings.size() == 1);
}

// SPDX-License-Identifier: BSD-3-Clause
#include <catch2/catch.hpp>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>

#include "rotacal/io/ballbar_file.hpp"

using namespace rotacal;

namespace {
const std::string kShared = ROTACAL_SHARED_DIR;

// Parse text and return the ParseError it raises (REQUIREs that it raises one).
template <typename Parse>
ParseError refusal(const std::string& text, Parse parse) {
  std::istringstream in(text);
  try {
    parse(in, "bad.csv");
  } catch (const ParseError& e) {
    return e;
  }
  FAIL("accepted a malformed file:\n" << text);
  throw;  // unreachable
}

const std::string kBallbarHead =
    "# format: rotacal-ballbar/1\n# machine: AC-trt\n# units: mm, deg, s\n"
    "# ballbar_length: 100.0000\n# pivot: 120.0000, 0.0000, 60.0000\n";
const std::string kBallbarColumns = "test,time,X,Y,Z,A,C,length\n";
const std::string kGoodRow =
    "sphere_xy,0.000,220.000000,0.000000,60.000000,0.000000,0.000000,99.9904419\n";

BallbarSession random_ballbar(std::mt19937& rng) {
  std::uniform_real_distribution<double> U(-500, 500);
  BallbarSession s;
  s.machine = MachineType::BC_trt;
  s.ballbar_length = 150.0 + U(rng) * 1e-3;
  s.pivot = {U(rng), U(rng), U(rng)};
  s.noise_um = 0.37;
  s.metadata = {{"operator", "J. Smith"}, {"temperature_C", "20.4"}};
  s.extra_columns = {"flag"};
  double t = 0.0;
  for (int i = 0; i < 50; ++i) {
    BallbarSample b;
    b.test = i < 25 ? "radial_B" : "axial_C";
    t += std::abs(U(rng)) * 1e-3;
    b.time = t;
    b.xyz = {U(rng), U(rng), U(rng)};
    b.tilt_deg = U(rng) / 5;
    b.rot_deg = U(rng) / 3;
    b.length = 150.0 + U(rng) * 1e-5;
    b.extra = {i % 7 ? "ok" : "gap"};
    s.samples.push_back(b);
  }
  s.annotations = {{10, "gap: 3 frames lost"}, {50, "stopped by operator"}};
  return s;
}
}  // namespace

TEST_CASE("the independent implementation's ballbar files load", "[io]") {
  const BallbarSession s = read_ballbar(kShared + "/data/ballbar_ac_table2.csv");
  CHECK(s.machine == MachineType::AC_trt);
  CHECK(s.ballbar_length == 100.0);
  CHECK(s.pivot.isApprox(Eigen::Vector3d(120, 0, 60)));
  CHECK_FALSE(s.noise_um.has_value());
  REQUIRE(s.samples.size() == 1804);
  CHECK(s.indices_of("sphere_xy").size() == 360);
  CHECK(s.indices_of("sphere_yz").size() == 181);
  CHECK(s.indices_of("sphere_zx").size() == 181);
  CHECK(s.indices_of("radial_A").size() == 181);
  CHECK(s.indices_of("axial_A").size() == 181);
  CHECK(s.indices_of("radial_C").size() == 360);
  CHECK(s.indices_of("axial_C").size() == 360);
  // First row, as printed in the file.
  CHECK(s.samples[0].test == "sphere_xy");
  CHECK(s.samples[0].xyz.isApprox(Eigen::Vector3d(220, 0, 60)));
  CHECK(s.samples[0].length == 100.0146021);
  const std::vector<std::string> tests = s.tests();
  CHECK(tests.front() == "sphere_xy");
  CHECK(tests.size() == 7);
  CHECK_NOTHROW(read_ballbar(kShared + "/data/ballbar_ac_random.csv"));
}

TEST_CASE("write-then-read of a ballbar session is exact", "[io]") {
  std::mt19937 rng(17);
  for (int k = 0; k < 5; ++k) {
    const BallbarSession s = random_ballbar(rng);
    std::istringstream in(format_ballbar(s));
    const BallbarSession r = parse_ballbar(in, "roundtrip");
    REQUIRE(r.samples.size() == s.samples.size());
    CHECK(r.machine == s.machine);
    CHECK(r.ballbar_length == s.ballbar_length);
    CHECK(r.pivot == s.pivot);
    CHECK(r.noise_um == s.noise_um);
    CHECK(r.extra_columns == s.extra_columns);
    for (std::size_t i = 0; i < s.samples.size(); ++i) {
      CHECK(r.samples[i].test == s.samples[i].test);
      CHECK(r.samples[i].time == s.samples[i].time);
      CHECK(r.samples[i].xyz == s.samples[i].xyz);
      CHECK(r.samples[i].tilt_deg == s.samples[i].tilt_deg);
      CHECK(r.samples[i].rot_deg == s.samples[i].rot_deg);
      CHECK(r.samples[i].length == s.samples[i].length);
      CHECK(r.samples[i].extra == s.samples[i].extra);
    }
    REQUIRE(r.annotations.size() == 2);
    CHECK(r.annotations[0].before_sample == 10);
    CHECK(r.annotations[0].text == "gap: 3 frames lost");
    CHECK(r.annotations[1].before_sample == 50);
    bool kept = false;
    for (const auto& kv : r.metadata) kept |= kv.first == "operator" && kv.second == "J. Smith";
    CHECK(kept);
  }
}

TEST_CASE("write_ballbar writes a file that reads back; bad paths raise IoError", "[io]") {
  std::mt19937 rng(3);
  const BallbarSession s = random_ballbar(rng);
  const std::string path = "test_io_roundtrip.csv";
  write_ballbar(s, path);
  const BallbarSession r = read_ballbar(path);
  CHECK(r.samples.back().length == s.samples.back().length);
  std::remove(path.c_str());
  CHECK_THROWS_AS(write_ballbar(s, "/nonexistent-dir/x.csv"), IoError);
  CHECK_THROWS_WITH(read_ballbar("/nonexistent-dir/x.csv"),
                    Catch::Contains("/nonexistent-dir/x.csv"));
}

TEST_CASE("malformed ballbar files are refused with the line that is wrong", "[io]") {
  struct Case {
    const char* what;
    std::string text;
    int line;
    const char* says;
  };
  const std::vector<Case> cases = {
      {"empty file", "", 0, "empty file"},
      {"blank file", "\n\n", 0, "empty file"},
      {"wrong format line",
       "# format: rotacal-ballbar/2\n" + kBallbarHead.substr(28) + kBallbarColumns + kGoodRow, 1,
       "rotacal-ballbar/2"},
      {"no format line", kBallbarHead.substr(28) + kBallbarColumns + kGoodRow, 1,
       "first line must be"},
      {"unknown machine",
       "# format: rotacal-ballbar/1\n# machine: XYZ-trt\n# ballbar_length: 100\n# pivot: 1,2,3\n" +
           kBallbarColumns + kGoodRow,
       2, "XYZ-trt"},
      {"missing column", kBallbarHead + "test,time,X,Y,Z,A,C\n" + kGoodRow, 6, "length"},
      {"text in a number",
       kBallbarHead + kBallbarColumns + kGoodRow + "sphere_xy,0.1,219.9,abc,60,0,0,99.99\n", 8,
       "'abc' is not a number"},
      {"NaN", kBallbarHead + kBallbarColumns + kGoodRow + "sphere_xy,0.1,219.9,1.7,60,0,0,nan\n", 8,
       "finite"},
      {"infinity", kBallbarHead + kBallbarColumns + kGoodRow + "sphere_xy,0.1,inf,1.7,60,0,0,99\n",
       8, "finite"},
      {"decreasing time",
       kBallbarHead + kBallbarColumns + "s,1.0,1,2,3,0,0,99\ns,0.5,1,2,3,0,0,99\n", 8,
       "time must not decrease"},
      {"too few fields", kBallbarHead + kBallbarColumns + "s,1.0,1,2,3,0,0\n", 7,
       "expected 8 fields"},
      {"no data rows", kBallbarHead + kBallbarColumns, 6, "no data rows"},
      {"B column on an AC machine", kBallbarHead + "test,time,X,Y,Z,B,C,length\n" + kGoodRow, 6,
       "does not belong to a AC-trt"},
      {"duplicate column", kBallbarHead + "test,time,X,X,Z,A,C,length\n" + kGoodRow, 6,
       "appears twice"},
      {"missing ballbar_length",
       "# format: rotacal-ballbar/1\n# machine: AC-trt\n# pivot: 1,2,3\n" + kBallbarColumns +
           kGoodRow,
       0, "ballbar_length"},
      {"pivot not three numbers",
       "# format: rotacal-ballbar/1\n# machine: AC-trt\n# ballbar_length: 100\n"
       "# pivot: 1,2\n" +
           kBallbarColumns + kGoodRow,
       4, "three numbers"},
      {"wrong units",
       "# format: rotacal-ballbar/1\n# machine: AC-trt\n# units: in, deg, s\n# ballbar_length: "
       "100\n"
       "# pivot: 1,2,3\n" +
           kBallbarColumns + kGoodRow,
       3, "units"},
      {"negative noise", kBallbarHead + "# noise_um: -1\n" + kBallbarColumns + kGoodRow, 6,
       "noise_um"},
  };
  for (const Case& c : cases) {
    INFO(c.what);
    const ParseError e = refusal(
        c.text, [](std::istream& in, const std::string& n) { return parse_ballbar(in, n); });
    CHECK(e.line() == c.line);
    CHECK(e.file() == "bad.csv");
    CHECK_THAT(e.what(), Catch::Contains(c.says));
    if (c.line > 0) CHECK_THAT(e.what(), Catch::Contains("bad.csv:" + std::to_string(c.line)));
  }
  // The column of a bad number is reported too (1-based character position).
  const ParseError e =
      refusal(kBallbarHead + kBallbarColumns + "s,0.1,219.9,abc,60,0,0,99\n",
              [](std::istream& in, const std::string& n) { return parse_ballbar(in, n); });
  CHECK(e.column() == 13);
}

TEST_CASE("appending writer flushes every row and keeps gap markers", "[io]") {
  std::mt19937 rng(5);
  const BallbarSession s = random_ballbar(rng);
  const std::string path = "test_io_append.csv";
  {
    std::ofstream old(path);
    old << "the previous recording\n";
  }
  {
    BallbarWriter w(path, s);
    for (int i = 0; i < 5; ++i) w.append(s.samples[static_cast<std::size_t>(i)]);
    w.annotate("gap: seq 17-19 missing");
    w.append(s.samples[5]);
    // Before close or destruction the rows are already on disk, in the temporary file; the
    // previous file is replaced only when the writer ends (the output rule).
    REQUIRE(w.writing_path() != path);
    {
      std::ifstream old(path);
      std::string line;
      std::getline(old, line);
      CHECK(line == "the previous recording");
    }
    const BallbarSession partial = read_ballbar(w.writing_path());
    CHECK(partial.samples.size() == 6);
    REQUIRE(partial.annotations.size() == 1);
    CHECK(partial.annotations[0].before_sample == 5);
    CHECK_THROWS_AS(w.append(s.samples[0]), InvalidArgument);  // time going backwards
  }
  CHECK(read_ballbar(path).samples.size() == 6);
  std::remove(path.c_str());
}

// SPDX-License-Identifier: BSD-3-Clause
#include <catch2/catch.hpp>
#include <cstdio>
#include <random>
#include <sstream>

#include "rotacal/io/probe_file.hpp"

using namespace rotacal;

namespace {
const std::string kShared = ROTACAL_SHARED_DIR;
const std::string kHead =
    "# format: rotacal-probe/1\n# machine: AC-trt\n# units: mm, deg, s\n# sphere: 150.0000, "
    "0.0000, 80.0000\n"
    "# sphere_diameter: 25.0000\n# stylus_diameter: 6.0000\n";
const std::string kColumns = "pose,time,X,Y,Z,A,C,nx,ny,nz\n";
const std::string kRow =
    "1,0.0,149.999348,0.000453,95.464574,0.0000,0.0000,0.000000,0.000000,-1.000000\n";
const std::string kRow2 =
    "1,2.0,163.408519,0.000291,87.741750,0.0000,0.0000,-0.866025,-0.000000,-0.500000\n";

// The line (and column) a text is refused at, with the message checked.
std::pair<int, int> refused_at(const std::string& text, const std::string& says) {
  std::istringstream in(text);
  try {
    parse_probe(in, "bad.csv");
  } catch (const ParseError& e) {
    CHECK_THAT(e.what(), Catch::Contains(says));
    CHECK_THAT(e.what(), Catch::StartsWith("bad.csv"));
    return {e.line(), e.column()};
  }
  FAIL("accepted:\n" << text);
  return {-1, -1};
}
}  // namespace

TEST_CASE("the independent implementation's probe file loads", "[io][probe]") {
  const ProbeSession s = read_probe(kShared + "/data/probe_ac_table2.csv");
  CHECK(s.machine == MachineType::AC_trt);
  CHECK(s.sphere == Eigen::Vector3d(150, 0, 80));
  CHECK(s.sphere_diameter == 25.0);
  CHECK(s.stylus_diameter == 6.0);
  CHECK(s.trigger_radius() == 15.5);
  REQUIRE(s.samples.size() == 120);
  CHECK(s.poses().size() == 24);
  CHECK(s.indices_of("2").size() == 5);
  CHECK(s.samples[1].xyz.x() == 163.408519);
  CHECK(s.samples[1].n.norm() == Approx(1.0).epsilon(1e-15));  // normalised on reading
  CHECK(s.samples[5].rot_deg == 30.0);
  CHECK(std::holds_alternative<ProbeSession>(
      read_instrument_session(kShared + "/data/probe_ac_table2.csv")));
  CHECK(std::holds_alternative<BallbarSession>(
      read_instrument_session(kShared + "/data/ballbar_ac_table2.csv")));
  CHECK(std::holds_alternative<RtestSession>(
      read_instrument_session(kShared + "/data/rtest_bc_oyama.csv")));
}

TEST_CASE("a probe session writes and reads back bit-identical", "[io][probe]") {
  ProbeSession s = read_probe(kShared + "/data/probe_ac_table2.csv");
  s.metadata.push_back({"operator", "someone"});
  s.noise_um = 0.5;
  const std::string text = format_probe(s);
  std::istringstream in(text);
  const ProbeSession t = parse_probe(in, "again.csv");
  REQUIRE(t.samples.size() == s.samples.size());
  for (std::size_t i = 0; i < s.samples.size(); ++i) {
    CHECK(t.samples[i].xyz == s.samples[i].xyz);
    CHECK(t.samples[i].n == s.samples[i].n);
    CHECK(t.samples[i].pose == s.samples[i].pose);
    CHECK(t.samples[i].tilt_deg == s.samples[i].tilt_deg);
    CHECK(t.samples[i].rot_deg == s.samples[i].rot_deg);
  }
  CHECK(t.noise_um == 0.5);
  CHECK(format_probe(t) == text);
  CHECK_THAT(text, Catch::Contains("# operator: someone"));
  // B before C on BC-trt: the rotary columns follow the chain.
  s.machine = MachineType::BC_trt;
  CHECK_THAT(format_probe(s), Catch::Contains("pose,time,X,Y,Z,B,C,nx,ny,nz"));
  s.samples[0].n = Eigen::Vector3d(0, 0, 2);
  CHECK_THROWS_AS(format_probe(s), InvalidArgument);
}

// A direction written to six decimals (norm off 1 by up to 1e-4, which the reader accepts and
// normalises) must come back from write and read unchanged: renormalising an already unit
// vector moved its last bit (found by fuzz_file_readers, seed regression-probe-direction-*).
TEST_CASE("a probe file's directions read, write and read back identical", "[io][probe]") {
  std::mt19937 rng(7);
  std::normal_distribution<double> g;
  std::string text = kHead + kColumns;
  for (int i = 0; i < 300; ++i) {
    const Eigen::Vector3d d = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
    char row[160];
    std::snprintf(row, sizeof row, "p%d,%d.0,150,0,95,0,0,%.6f,%.6f,%.6f\n", i, i, d.x(), d.y(),
                  d.z());
    text += row;
  }
  std::istringstream in(text);
  const std::string once = format_probe(parse_probe(in, "six_decimals.csv"));
  std::istringstream again(once);
  CHECK(format_probe(parse_probe(again, "again.csv")) == once);
}

TEST_CASE("bad probe files are refused naming line and column", "[io][probe]") {
  CHECK(refused_at(kHead + kColumns + kRow + "1,2.0,163.4,0.0,87.7,0.0,0.0,-0.9,0.0,-0.5\n", "norm")
            .first == 9);
  CHECK(refused_at(kHead + kColumns + kRow + "1,2.0,163.4,0.0,87.7,0.0,0.0,-0.9,0.0,-0.5\n", "norm")
            .second == 30);
  CHECK(refused_at(kHead + kColumns + kRow + kRow2 + "1,1.0,1,2,3,0,0,0,0,-1\n", "time").first ==
        10);
  CHECK(refused_at(kHead + kColumns + kRow + "1,2.0,1,2,3,15,0,0,0,-1\n",
                   "held at one rotary position")
            .first == 9);
  CHECK(refused_at(kHead + kColumns + "1,0.0,nan,0,0,0,0,0,0,-1\n", "X").first == 8);
  CHECK(refused_at(kHead + kColumns + "1,0.0,abc,0,0,0,0,0,0,-1\n", "not a number").second == 7);
  CHECK(refused_at(kHead + "pose,time,X,Y,Z,A,C,nx,ny\n" + kRow, "missing required column 'nz'")
            .first == 7);
  CHECK(refused_at(kHead + "pose,time,X,Y,Z,B,C,nx,ny,nz\n" + kRow, "does not belong").first == 7);
  std::string no_sphere = kHead;
  no_sphere.replace(no_sphere.find("# sphere: "), 36, "");
  refused_at(no_sphere + kColumns + kRow, "missing metadata 'sphere'");
  std::string zero_d = kHead;
  zero_d.replace(zero_d.find("25.0000"), 7, "0");
  CHECK(refused_at(zero_d + kColumns + kRow, "sphere_diameter must be > 0").first == 5);
  std::string neg_stylus = kHead;
  neg_stylus.replace(neg_stylus.find("6.0000"), 6, "-6");
  CHECK(refused_at(neg_stylus + kColumns + kRow, "stylus_diameter").first == 6);
  refused_at("# format: rotacal-ballbar/1\n" + kHead.substr(kHead.find('\n') + 1) + kColumns + kRow,
             "rotacal-probe/1");
  CHECK(refused_at(kHead + kColumns + "1,0.0,1,2\n", "expected 10 fields").first == 8);
  CHECK_THROWS_AS(read_probe("/nonexistent/probe.csv"), IoError);
}

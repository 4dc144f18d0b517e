// SPDX-License-Identifier: BSD-3-Clause
#include <catch2/catch.hpp>
#include <cstdio>
#include <sstream>

#include "rotacal/io/ballbar_file.hpp"

using namespace rotacal;

namespace {
const std::string kShared = ROTACAL_SHARED_DIR;
const std::string kHead =
    "# format: rotacal-rtest/1\n# machine: BC-trt\n# units: mm, deg, s\n"
    "# nest.1: 100.0000, 0.0000, 60.0000\n# nest.2: 0.0000, -120.0000, 140.0000\n";
const std::string kColumns = "setup,time,B,C,X,Y,Z,dx,dy,dz\n";
const std::string kRow =
    "1,0.0,-90.0000,0.0000,-60.000000,0.000000,100.000000,0.0058340,-0.0301318,-0.0129457\n";

int refused_line(const std::string& text, const std::string& says) {
  std::istringstream in(text);
  try {
    parse_rtest(in, "bad.csv");
  } catch (const ParseError& e) {
    CHECK_THAT(e.what(), Catch::Contains(says));
    return e.line();
  }
  FAIL("accepted:\n" << text);
  return -1;
}
}  // namespace

TEST_CASE("the independent implementation's R-test file loads", "[io]") {
  const RtestSession s = read_rtest(kShared + "/data/rtest_bc_oyama.csv");
  CHECK(s.machine == MachineType::BC_trt);
  REQUIRE(s.nests.size() == 2);
  CHECK(s.nests.at("2").isApprox(Eigen::Vector3d(0, -120, 140)));
  REQUIRE(s.samples.size() == 168);
  CHECK(s.indices_of("1").size() == 84);
  CHECK(s.samples[0].tilt_deg == -90.0);
  REQUIRE(s.samples[0].d.has_value());
  CHECK(s.samples[0].d->x() == 0.0036884);
  CHECK_FALSE(s.samples[0].raw.has_value());
  CHECK(std::holds_alternative<RtestSession>(read_session(kShared + "/data/rtest_bc_oyama.csv")));
  CHECK(std::holds_alternative<BallbarSession>(
      read_session(kShared + "/data/ballbar_ac_table2.csv")));
}

TEST_CASE("R-test write-then-read is exact, with raw probe readings too", "[io]") {
  RtestSession s = read_rtest(kShared + "/data/rtest_bc_oyama.csv");
  s.probe_dirs = {
      {1, Eigen::Vector3d(1, 0, 0)}, {2, Eigen::Vector3d(0, 1, 0)}, {3, Eigen::Vector3d(0, 0, 1)}};
  for (auto& r : s.samples) r.raw = Eigen::Vector3d(r.d->x() + 1e-7, r.d->y() / 3.0, -r.d->z());
  s.noise_um = 0.3;
  std::istringstream in(format_rtest(s));
  const RtestSession r = parse_rtest(in, "roundtrip");
  REQUIRE(r.samples.size() == s.samples.size());
  CHECK(r.probe_dirs.size() == 3);
  CHECK(r.noise_um == s.noise_um);
  for (std::size_t i = 0; i < s.samples.size(); ++i) {
    CHECK(*r.samples[i].d == *s.samples[i].d);
    CHECK(*r.samples[i].raw == *s.samples[i].raw);
    CHECK(r.samples[i].xyz == s.samples[i].xyz);
    CHECK(r.samples[i].setup == s.samples[i].setup);
  }
}

TEST_CASE("malformed R-test files are refused with the line that is wrong", "[io]") {
  CHECK(refused_line(kHead + "setup,time,B,C,X,Y,Z\n" + kRow, "dx,dy,dz or d1,d2,d3") == 6);
  CHECK(refused_line(kHead + kColumns + "3,0.0,0,0,1,2,3,0,0,0\n", "nest.3") == 7);
  CHECK(refused_line(kHead + kColumns + kRow + "1,1.0,0,0,1,2,3,0,x,0\n", "'x' is not a number") ==
        8);
  CHECK(refused_line(kHead + "setup,time,B,C,X,Y,Z,d1,d2,d3\n" + kRow, "probe.1.dir") == 0);
  CHECK(refused_line(kHead + "setup,time,A,C,X,Y,Z,dx,dy,dz\n" + kRow,
                     "does not belong to a BC-trt") == 6);
  CHECK(refused_line("# format: rotacal-rtest/1\n# machine: BC-trt\n# probe.1.dir: 1, 1, 0\n" +
                         kColumns + kRow,
                     "unit vector") == 3);
  CHECK(refused_line(kHead + kColumns + kRow + "1,-1.0,0,0,1,2,3,0,0,0\n",
                     "time must not decrease") == 8);
}

TEST_CASE("R-test appending writer", "[io]") {
  const RtestSession s = read_rtest(kShared + "/data/rtest_bc_oyama.csv");
  const std::string path = "test_io_rtest_append.csv";
  {
    RtestWriter w(path, s, false);
    for (int i = 0; i < 3; ++i) w.append(s.samples[static_cast<std::size_t>(i)]);
    w.annotate("probe 2 out of range");
    CHECK(read_rtest(w.writing_path()).samples.size() == 3);
    CHECK_THROWS_AS(RtestWriter("x.csv", s, true), InvalidArgument);  // raw needs probe dirs
  }
  CHECK(read_rtest(path).samples.size() == 3);  // renamed over the target when destroyed
  std::remove(path.c_str());
}

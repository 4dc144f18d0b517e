// SPDX-License-Identifier: BSD-3-Clause
// The probing program (probe/nc_program.hpp): one G38.2 and one LOG per touch of the pattern,
// in LinuxCNC words only; limits, travel and moves through the sphere refused; the log read
// back into the plan's rows. Its moves are checked against LinuxCNC's own interpreter and the
// reference simulator in tests/python/test_probe_plan.py.
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>

#include "rotacal/probe/nc_program.hpp"

using namespace rotacal;

namespace {
int count(const std::string& text, const std::string& word) {
  int n = 0;
  for (std::size_t at = text.find(word); at != std::string::npos; at = text.find(word, at + 1)) ++n;
  return n;
}
}  // namespace

TEST_CASE("one G38.2 and one LOG per touch, between LOGOPEN and LOGCLOSE", "[probe][plan]") {
  const ProbePattern P = default_probe_pattern(MachineType::AC_trt);
  const std::string text = write_probe_nc_program(MachineType::AC_trt, P, NcDialect::linuxcnc);
  const int touches = static_cast<int>(P.poses_deg.size() * P.directions.size());
  CHECK(count(text, "G38.2 ") == touches);
  CHECK(count(text, "(LOG,") == touches);
  CHECK(count(text, "(LOGOPEN,rotacal_probe.log)") == 1);
  CHECK(text.find("(LOGCLOSE)\nM2\n") != std::string::npos);
  CHECK(text.find("(LOG,24 5 #5061 #5062 #5063)") != std::string::npos);
  for (NcDialect d : {NcDialect::heidenhain, NcDialect::siemens, NcDialect::fanuc})
    CHECK_THROWS_WITH(
        write_probe_nc_program(MachineType::AC_trt, P, d),
        Catch::Contains("no checkable probing words") && Catch::Contains(to_string(d)));
}

TEST_CASE("moves start outside the trigger sphere and end inside it, along n", "[probe][plan]") {
  const ProbePattern P = default_probe_pattern(MachineType::BC_trt);
  double z = 0.0;
  const std::vector<ProbeMove> moves = probe_moves(MachineType::BC_trt, P, {}, &z);
  REQUIRE(moves.size() == P.poses_deg.size() * P.directions.size());
  for (const ProbeMove& m : moves) {
    CHECK((m.target - m.start).normalized().isApprox(m.n, 1e-12));
    CHECK((m.target - m.start).norm() == Approx(5.0 + 2.0));
    CHECK(z > m.start.z());
  }
}

TEST_CASE("limits, travel and a way up through the sphere are refused", "[probe][plan]") {
  ProbePattern P = default_probe_pattern(MachineType::AC_trt);
  const MachineType head = parse_machine_type("B-head-C-table");  // B limited to -110..110 deg
  ProbePattern beyond = default_probe_pattern(head);
  CHECK_NOTHROW(probe_moves(head, beyond, {}));
  beyond.poses_deg.push_back({-150.0, 0.0});
  CHECK_THROWS_WITH(probe_moves(head, beyond, {}),
                    Catch::Contains("B -150 deg is outside the axis limits"));
  ProbePattern high = P;
  high.sphere.z() = 380.0;  // the retract plane above Z's travel (-300..400 mm)
  CHECK_THROWS_WITH(probe_moves(MachineType::AC_trt, high, {}),
                    Catch::Contains("Z") && Catch::Contains("travel"));
  ProbePattern below = P;
  below.directions.push_back(
      Eigen::Vector3d(0.0, 0.0, 1.0));  // from underneath: the way up hits it
  CHECK_THROWS_WITH(probe_moves(MachineType::AC_trt, below, {}),
                    Catch::Contains("passes through the sphere"));
  ProbeProgramOptions o;
  o.overtravel_mm = 20.0;
  CHECK_THROWS_AS(probe_moves(MachineType::AC_trt, P, o), InvalidArgument);
}

TEST_CASE("the log is read back into the plan's rows, and a bad log is refused by line",
          "[probe][plan]") {
  ProbePattern P = default_probe_pattern(MachineType::AC_trt);
  P.poses_deg.resize(2);
  ProbeSimOptions so;
  so.pattern = P;
  so.noise_um = 0.0;
  MachineModel nominal = MachineModel::nominal(MachineType::AC_trt);
  const ProbeSession plan = simulate_probe(nominal, so).session;
  const std::string path =
      (std::filesystem::temp_directory_path() / "rotacal_test_probe.log").string();
  {
    std::ofstream f(path);
    for (std::size_t i = 0; i < plan.samples.size(); ++i)
      f << i / 5 + 1 << " " << i % 5 + 1 << " " << 1.0 + i << " 2.000000 3.000000\n";
  }
  const ProbeSession s = read_linuxcnc_probe_log(path, plan);
  REQUIRE(s.samples.size() == plan.samples.size());
  CHECK(s.samples[7].xyz.x() == 8.0);
  CHECK(s.samples[7].n == plan.samples[7].n);
  {
    std::ofstream f(path);
    f << "1 1 1 2 3\n1 3 1 2 3\n";
  }
  CHECK_THROWS_WITH(read_linuxcnc_probe_log(path, plan),
                    Catch::Contains(":2:") && Catch::Contains("out of order"));
  {
    std::ofstream f(path);
    f << "1 1 1 2\n";
  }
  CHECK_THROWS_AS(read_linuxcnc_probe_log(path, plan), ParseError);
  std::filesystem::remove(path);
}

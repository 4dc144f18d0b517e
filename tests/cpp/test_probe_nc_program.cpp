// SPDX-License-Identifier: BSD-3-Clause
// The probing program (probe/nc_program.hpp): one G38.2 and one LOG per touch of the pattern,
// in LinuxCNC words only; limits, travel and moves through the sphere refused; the log read
// back into the plan's rows. Its moves are checked against LinuxCNC's own interpreter and the
// reference simulator in tests/python/test_probe_plan.py.
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <iomanip>

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
  // A latch lies on its commanded line (the plan's X, Y, Z along n), here 1 um further per row.
  auto on_line = [&](std::size_t i, double along) {
    return Eigen::Vector3d(plan.samples[i].xyz + along * plan.samples[i].n.normalized());
  };
  auto write = [&](const std::vector<Eigen::Vector3d>& latched) {
    std::ofstream f(path);
    f << std::setprecision(12);
    for (std::size_t i = 0; i < latched.size(); ++i)
      f << i / 5 + 1 << " " << i % 5 + 1 << " " << latched[i].x() << " " << latched[i].y() << " "
        << latched[i].z() << "\n";
  };
  std::vector<Eigen::Vector3d> latched;
  for (std::size_t i = 0; i < plan.samples.size(); ++i) latched.push_back(on_line(i, 1e-3 * i));
  write(latched);
  const ProbeSession s = read_linuxcnc_probe_log(path, plan);
  REQUIRE(s.samples.size() == plan.samples.size());
  CHECK((s.samples[7].xyz - on_line(7, 7e-3)).norm() < 1e-9);
  CHECK(s.samples[7].n == plan.samples[7].n);
  // 1.5 mm across its line (perpendicular to n): not the touch commanded, refused by line.
  const Eigen::Vector3d n3 = plan.samples[3].n.normalized();
  const Eigen::Vector3d across = n3.cross(Eigen::Vector3d::UnitX()).norm() > 0.1
                                     ? n3.cross(Eigen::Vector3d::UnitX()).normalized()
                                     : n3.cross(Eigen::Vector3d::UnitY()).normalized();
  latched[3] += 1.5 * across;
  write(latched);
  CHECK_THROWS_WITH(read_linuxcnc_probe_log(path, plan),
                    Catch::Contains(":4:") && Catch::Contains("off its commanded line"));
  CHECK_NOTHROW(read_linuxcnc_probe_log(path, plan, 2.0));  // a wider bound takes it
  {
    std::ofstream f(path);
    f << std::setprecision(12) << "1 1 " << latched[0].x() << " " << latched[0].y() << " "
      << latched[0].z() << "\n1 3 1 2 3\n";
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

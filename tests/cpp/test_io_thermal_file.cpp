// SPDX-License-Identifier: BSD-3-Clause
// The epoch column and `# duty.N:` lines of a thermal session (io/thermal_file.hpp).
#include <unistd.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "rotacal/io/thermal_file.hpp"

using namespace rotacal;

namespace {
const std::string kShared = ROTACAL_SHARED_DIR;
const std::string kHead =
    "# format: rotacal-probe/1\n# machine: AC-trt\n# units: mm, deg, s\n"
    "# sphere: 150.0000, 0.0000, 80.0000\n# sphere_diameter: 25.0000\n"
    "# stylus_diameter: 6.0000\n";
const std::string kColumns = "pose,time,X,Y,Z,A,C,nx,ny,nz,epoch\n";
std::string row(int pose, double t, int epoch) {
  return std::to_string(pose) + "," + std::to_string(t) +
         ",149.999348,0.000453,95.464574,0.0000,0.0000,0.000000,0.000000,-1.000000," +
         std::to_string(epoch) + "\n";
}

std::string write_temp(const std::string& text) {
  static int n = 0;
  const std::string path =
      (std::filesystem::temp_directory_path() /
       ("rotacal_thermal_" + std::to_string(::getpid()) + "_" + std::to_string(n++) + ".csv"))
          .string();
  std::ofstream(path) << text;
  return path;
}

// The line a text is refused at, the message checked.
int refused_at(const std::string& text, const std::string& says) {
  const std::string path = write_temp(text);
  try {
    read_thermal_session(path);
  } catch (const ParseError& e) {
    CHECK_THAT(e.what(), Catch::Contains(says));
    CHECK_THAT(e.what(), Catch::StartsWith(path));
    std::filesystem::remove(path);
    return e.line();
  }
  std::filesystem::remove(path);
  FAIL("accepted:\n" << text);
  return -1;
}
}  // namespace

TEST_CASE("the shared thermal probe session reads with its duty and epochs", "[io][thermal]") {
  const ThermalSession t = read_thermal_session(kShared + "/data/thermal_probe_ac.csv");
  const auto& s = std::get<ProbeSession>(t.session);
  REQUIRE(s.samples.size() == 1480);
  REQUIRE(t.thermal.duty.size() == 2);
  CHECK(t.thermal.duty[0].time == 0.0);
  CHECK(t.thermal.duty[0].speed_of('C') == 300.0);
  CHECK(t.thermal.duty[1].time == 14400.0);
  CHECK(t.thermal.duty[1].speed_of('C') == 0.0);
  CHECK(t.thermal.epoch.front() == 1);
  CHECK(t.thermal.epoch.back() == 37);
  CHECK(t.thermal.epoch_spans().size() == 37);
  CHECK(t.thermal.axes() == std::vector<char>{'C'});
  CHECK(t.thermal.tested_speed('C') == 300.0);
  CHECK(is_thermal_session(kShared + "/data/thermal_probe_ac.csv"));
  CHECK_FALSE(is_thermal_session(kShared + "/data/probe_ac_table2.csv"));
  // u: 0 in epoch 1 (0-120 s), 3 until epoch 2 (600 s), 0 in it (600-720 s), 3 again.
  const HeatInput h = t.thermal.heat_input('C');
  REQUIRE(h.start.size() >= 4);
  CHECK(h.start[0] == 0.0);
  CHECK(h.u[0] == 0.0);
  CHECK(h.start[1] == 120.0);
  CHECK(h.u[1] == 3.0);
  CHECK(h.start[2] == 600.0);
  CHECK(h.u[2] == 0.0);
  CHECK(h.start[3] == 720.0);
}

TEST_CASE("the shared thermal R-test session reads", "[io][thermal]") {
  const ThermalSession t = read_thermal_session(kShared + "/data/thermal_rtest_bc.csv");
  CHECK(std::get<RtestSession>(t.session).samples.size() == t.thermal.epoch.size());
  CHECK(t.thermal.tested_speed('C') == 200.0);
  CHECK(t.thermal.epoch.back() == 28);
}

TEST_CASE("lag state: closed form by hand and the one-pass form agree", "[thermal]") {
  // u = 0 on [0, 10), 3 on [10, 100), 1.5 from 100 s on; tau 40 s.
  const HeatInput h{{0.0, 10.0, 100.0}, {0.0, 3.0, 1.5}};
  const double y100 = 3.0 * (1.0 - std::exp(-90.0 / 40.0));
  const std::vector<double> t{0.0, 10.0, 50.0, 100.0, 160.0};
  const std::vector<double> want{0.0, 0.0, 3.0 * (1.0 - std::exp(-1.0)), y100,
                                 1.5 + (y100 - 1.5) * std::exp(-1.5)};
  const std::vector<double> all = lag_states(h, t, 40.0);
  for (std::size_t i = 0; i < t.size(); ++i) {
    CHECK(lag_state(h, t[i], 40.0) == Approx(want[i]).margin(1e-15));
    CHECK(all[i] == Approx(want[i]).margin(1e-15));
  }
  CHECK(thermal_tau(std::log(8.0)) == Approx(2400.0));
  // The tracker continues row after row, and starts over when a row is not the next one.
  LagTracker<double> track;
  for (int pass = 0; pass < 2; ++pass)
    for (std::size_t i = 0; i < t.size(); ++i)
      CHECK(track.at(static_cast<long>(i), h, t[i], 40.0) == Approx(want[i]).margin(1e-15));
  CHECK(track.at(2, h, t[2], 40.0) == Approx(want[2]).margin(1e-15));
}

TEST_CASE("thermal sessions refused by file and line", "[io][thermal]") {
  const std::string rows = row(1, 0, 1) + row(1, 2, 1) + row(2, 600, 2);
  // A duty naming an axis the machine lacks (AC-trt has A and C).
  CHECK(refused_at(kHead + "# duty.1: 0, B=300\n" + kColumns + rows, "names axis 'B'") == 7);
  // Decreasing epochs: line 11 is the third row.
  CHECK(refused_at(kHead + "# duty.1: 0, C=300\n" + kColumns + row(1, 0, 2) + row(1, 2, 2) +
                       row(2, 600, 1),
                   "epochs never decrease") == 11);
  // Duty lines without an epoch column.
  const std::string plain =
      "pose,time,X,Y,Z,A,C,nx,ny,nz\n"
      "1,0.0,149.999348,0.000453,95.464574,0.0000,0.0000,0,0,-1\n";
  CHECK(refused_at(kHead + "# duty.1: 0, C=300\n" + plain, "need an 'epoch' column") == 7);
  // TIME not increasing, negative; entries not consecutive; not AXIS=SPEED; epoch 0 or 1.5.
  CHECK(refused_at(kHead + "# duty.1: 100, C=300\n# duty.2: 100, C=0\n" + kColumns + rows,
                   "must be after duty.1") == 8);
  CHECK(refused_at(kHead + "# duty.1: -5, C=300\n" + kColumns + rows, "duty.1 TIME") == 7);
  CHECK(refused_at(kHead + "# duty.1: 0, C=300\n# duty.3: 9, C=0\n" + kColumns + rows,
                   "duty.2 is missing") == 0);
  CHECK(refused_at(kHead + "# duty.1: 0, C:300\n" + kColumns + rows, "AXIS=SPEED") == 7);
  CHECK(refused_at(kHead + "# duty.1: 0, C=300\n# duty.02: 9, C=0\n" + kColumns + rows,
                   "is not a duty.N entry") == 8);
  CHECK(refused_at(kHead + "# duty.1: 0, C=fast\n" + kColumns + rows, "not a number") == 7);
  CHECK(refused_at(kHead + kColumns + row(1, 0, 0), "epoch") == 8);
  CHECK(refused_at(kHead + kColumns + "1,0.0,149.9,0.0,95.4,0,0,0,0,-1,1.5\n", "not an integer") ==
        8);
}

TEST_CASE("an epoch column without duty is an ordinary session; early duty warns",
          "[io][thermal]") {
  const std::string rows = row(1, 10, 1) + row(1, 12, 1);
  const std::string p1 = write_temp(kHead + kColumns + rows);
  const ThermalSession a = read_thermal_session(p1);
  CHECK(a.thermal.duty.empty());
  CHECK(a.thermal.axes().empty());
  const std::string p2 =
      write_temp(kHead + "# duty_notes: spindle off\n# duty.1: 0, C=-300\n" + kColumns + rows);
  const ThermalSession b = read_thermal_session(p2);
  CHECK(b.thermal.tested_speed('C') == 300.0);
  REQUIRE(b.warnings.size() == 1);
  CHECK_THAT(b.warnings[0], Catch::Contains("starts at 0 at the first row"));
  std::filesystem::remove(p1);
  std::filesystem::remove(p2);
}

TEST_CASE("the ordinary readers pool a thermal session's epochs and warn that it drifts",
          "[io][thermal]") {
  const ProbeSession p = read_probe(kShared + "/data/thermal_probe_ac.csv");
  CHECK(p.samples.size() == 1480);
  CHECK(std::count(p.warnings.begin(), p.warnings.end(), kThermalSessionPooled) == 1);
  const auto r = std::get<RtestSession>(read_session(kShared + "/data/thermal_rtest_bc.csv"));
  CHECK(std::count(r.warnings.begin(), r.warnings.end(), kThermalSessionPooled) == 1);
  CHECK(read_probe(kShared + "/data/probe_ac_table2.csv").warnings.empty());
  const ThermalSession t = read_thermal_session(kShared + "/data/thermal_probe_ac.csv");
  CHECK(t.warnings.empty());
}

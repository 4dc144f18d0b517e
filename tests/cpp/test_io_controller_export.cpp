// SPDX-License-Identifier: BSD-3-Clause
// Tests of the controller exports (rotacal/io/controller_export.hpp): each public kinematics is
// re-implemented here from the controller's documented formulas, fed only with the exported
// text, and must put the table point where rotacal's identified model does (0.1 um) over the
// travel, for the errors the controller can hold.
#include <Eigen/Geometry>
#include <catch2/catch.hpp>
#include <cmath>
#include <map>
#include <random>
#include <sstream>

#include "rotacal/core/error.hpp"
#include "rotacal/io/controller_export.hpp"
#include "rotacal/kinematics/machine.hpp"

using namespace rotacal;

namespace {

constexpr double kDeg = M_PI / 180.0;

ExportInput random_identification(MachineType m, std::mt19937& rng, bool tilts) {
  std::normal_distribution<double> N(0.0, 1.0);
  ExportInput in;
  in.machine = m;
  for (int i = 0; i < 8; ++i) {
    const bool angle = location_error_is_angle(i);
    in.errors.v[i] = angle ? (tilts ? 5e-5 * N(rng) : 0.0) : 0.05 * N(rng);
    in.covariance(i, i) = angle ? 1e-12 : 1e-8;
  }
  in.source = "test.csv";
  return in;
}

// "name value" pairs from the export text: LinuxCNC "setp name value", Siemens "name=value",
// ISG "name  value"; comment lines skipped.
std::map<std::string, double> values_in(const std::string& text) {
  std::map<std::string, double> out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line[0] == ';') continue;
    if (line.rfind("setp ", 0) == 0) line = line.substr(5);
    const std::size_t eq = line.find('=');
    if (eq != std::string::npos) line[eq] = ' ';
    std::istringstream ls(line);
    std::string name, value;
    ls >> name >> value;
    char* end = nullptr;
    const double v = std::strtod(value.c_str(), &end);
    if (end != value.c_str() && *end == '\0') out[name] = v;
  }
  return out;
}

Eigen::Matrix3d rot(const Eigen::Vector3d& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

// Travel: table points within 200 mm of the pivot, tilt -90..90 deg, C a full turn.
template <typename Controller>
double worst_deviation_um(MachineType m, const ExportInput& in, const Eigen::Vector3d& origin,
                          Controller machine) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> q(-200.0, 200.0), tilt(-90.0, 90.0), c(0.0, 360.0);
  double worst = 0.0;
  for (int k = 0; k < 500; ++k) {
    const Eigen::Vector3d p(q(rng), q(rng), q(rng));
    const RotaryAngles<double> a{tilt(rng) * kDeg, c(rng) * kDeg};
    const Eigen::Vector3d expected =
        origin + forward(m, in.errors, a, p);  // rotacal's identified model
    worst = std::max(worst, 1e3 * (machine(origin + p, a) - expected).norm());
  }
  return worst;
}

}  // namespace

TEST_CASE(
    "LinuxCNC: trtfuncs.c's inverse kinematics with the exported pins is the identified model") {
  std::mt19937 rng(11);
  for (MachineType m : {MachineType::AC_trt, MachineType::BC_trt}) {
    const bool ac = m == MachineType::AC_trt;
    const std::string kins = ac ? "xyzac-trt-kins." : "xyzbc-trt-kins.";
    const ExportInput in = random_identification(m, rng, /*tilts=*/false);  // it holds no tilts
    // The kinematics active during the test: rotary axes meeting at the pivot (120, -40, 55).
    const Eigen::Vector3d pivot(120, -40, 55);
    ExportOptions o;
    o.current_given = true;
    o.current = {{kins + "x-rot-point", pivot.x()},
                 {kins + "y-rot-point", pivot.y()},
                 {kins + "z-rot-point", 20.0},
                 {kins + "z-offset", pivot.z() - 20.0}};
    const ControllerExport ex = export_kinematics(Controller::linuxcnc, in, o);
    const auto pins = values_in(ex.text);
    REQUIRE(pins.count(kins + "x-rot-point"));
    CHECK(pins.count(kins + (ac ? "x-offset" : "y-offset")) == 0);  // never read by the module
    // trtfuncs.c, world -> joints (default directions): J = r + d + R_t(t)[Rz(C)(P - r) - d].
    const Eigen::Vector3d r(pins.at(kins + "x-rot-point"), pins.at(kins + "y-rot-point"),
                            pins.at(kins + "z-rot-point"));
    const Eigen::Vector3d d =
        ac ? Eigen::Vector3d(0, pins.at(kins + "y-offset"), pins.at(kins + "z-offset"))
           : Eigen::Vector3d(pins.at(kins + "x-offset"), 0, pins.at(kins + "z-offset"));
    const Eigen::Vector3d tilt_axis = ac ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
    auto joints = [&](const Eigen::Vector3d& P, const RotaryAngles<double>& a) -> Eigen::Vector3d {
      return r + d + rot(tilt_axis, a.tilt) * (rot(Eigen::Vector3d::UnitZ(), a.rot) * (P - r) - d);
    };
    CHECK(worst_deviation_um(m, in, pivot, joints) < 0.1);
    // Before the correction (the current pins) the machine is off by the errors: the test can fail.
    ExportInput zero = in;
    zero.errors.v.setZero();
    const auto before = values_in(export_kinematics(Controller::linuxcnc, zero, o).text);
    CHECK(std::abs(before.at(kins + "x-rot-point") - pins.at(kins + "x-rot-point")) ==
          Approx(std::abs(in.errors.v[4])).margin(1e-6));
    // The tilts it cannot hold are listed as such, with their values, not dropped.
    REQUIRE(ex.errors.size() == 8);
    CHECK_FALSE(ex.errors[2].held);
    CHECK(ex.errors[0].held);
    CHECK(ex.text.find("NOT HELD") != std::string::npos);
  }
}

TEST_CASE(
    "Siemens: the type P toolholder chain with the exported $TC_CARR is the identified model") {
  std::mt19937 rng(12);
  for (MachineType m : {MachineType::AC_trt, MachineType::BC_trt}) {
    const ExportInput in = random_identification(m, rng, /*tilts=*/true);
    ExportOptions o;
    o.toolholder = 2;
    // Active: the reference point at the pivot, axes as nominal but the tilt axis written as -X or
    // -Y (a table that turns the other way is described with v negated; angles negate too).
    const double sense = -1.0;
    o.current_given = true;
    if (m == MachineType::AC_trt)
      o.current["$TC_CARR7[2]"] = sense;
    else
      o.current["$TC_CARR8[2]"] = sense;
    o.current["$TC_CARR12[2]"] = 1.0;
    const ControllerExport ex = export_kinematics(Controller::siemens, in, o);
    const auto v = values_in(ex.text);
    auto vec = [&](int n) {
      return Eigen::Vector3d(v.at("$TC_CARR" + std::to_string(n) + "[2]"),
                             v.at("$TC_CARR" + std::to_string(n + 1) + "[2]"),
                             v.at("$TC_CARR" + std::to_string(n + 2) + "[2]"));
    };
    const Eigen::Vector3d l2 = vec(4), v1 = vec(7), v2 = vec(10), l3 = vec(15), l4 = vec(18);
    CHECK(v1.norm() == Approx(1.0).epsilon(1e-8));
    // W1 manual, type P: x = l2 + R(v1, a1)(l3 + R(v2, a2)(l4 + q)), right-handed about v.
    auto machine = [&](const Eigen::Vector3d& q, const RotaryAngles<double>& a) -> Eigen::Vector3d {
      return l2 + rot(v1, sense * a.tilt) * (l3 + rot(v2, a.rot) * (l4 + q));
    };
    CHECK(worst_deviation_um(m, in, Eigen::Vector3d::Zero(), machine) < 0.1);
    for (const ErrorDisposition& e : ex.errors) CHECK(e.held);
  }
}

TEST_CASE(
    "ISG: the universal kinematic with the exported points and orientations is the identified "
    "model") {
  std::mt19937 rng(13);
  for (MachineType m : {MachineType::AC_trt, MachineType::BC_trt}) {
    const ExportInput in = random_identification(m, rng, /*tilts=*/true);
    const Eigen::Vector3d pivot(300, 250,
                                -400);  // the machine zero is elsewhere: points are absolute
    ExportOptions o;
    o.current_given = true;
    for (int a = 0; a < 2; ++a)
      for (int c = 0; c < 3; ++c)
        o.current["trafo[0].axis[" + std::to_string(a) + "].point[" + std::to_string(c) + "]"] =
            pivot[c] * 1e4;
    const ControllerExport ex = export_kinematics(Controller::isg, in, o);
    const auto v = values_in(ex.text);
    auto vec = [&](int axis, const std::string& what, double scale) {
      Eigen::Vector3d x;
      for (int c = 0; c < 3; ++c)
        x[c] = scale * v.at("trafo[0].axis[" + std::to_string(axis) + "]." + what + "[" +
                            std::to_string(c) + "]");
      return x;
    };
    const Eigen::Vector3d pC = vec(0, "point", 1e-4), oC = vec(0, "orientation", 1.0);
    const Eigen::Vector3d pT = vec(1, "point", 1e-4), oT = vec(1, "orientation", 1.0);
    // Workpiece coordinates of a machine point: the chain C, tilt from the workpiece, each a
    // right-handed rotation about its orientation (negated directions on the workpiece side);
    // the machine point of a workpiece point is its inverse.
    auto machine = [&](const Eigen::Vector3d& q, const RotaryAngles<double>& a) -> Eigen::Vector3d {
      const Eigen::Vector3d y = pC + rot(oC, -a.rot) * (q - pC);
      return pT + rot(oT, -a.tilt) * (y - pT);
    };
    CHECK(worst_deviation_um(m, in, pivot, machine) < 0.1);
  }
}

TEST_CASE("unobservable errors are not applied, and the parameters they feed keep their value") {
  std::mt19937 rng(14);
  ExportInput in = random_identification(MachineType::AC_trt, rng, false);
  in.observable[4] = false;  // E_X0C
  const ControllerExport ex = export_kinematics(Controller::linuxcnc, in);
  CHECK(ex.values[0].corrected == 0.0);  // x-rot-point: only E_X0C feeds it
  CHECK_FALSE(ex.errors[4].held);
  CHECK(ex.errors[4].where.find("not determined") != std::string::npos);
  CHECK(ex.text.find("NOT GIVEN") != std::string::npos);  // no current values: said so
}

TEST_CASE("sigma of a parameter that carries two errors uses their covariance") {
  ExportInput in;
  in.machine = MachineType::AC_trt;
  in.covariance(0, 0) = 4e-6;  // E_Y0A: 2 um
  in.covariance(5, 5) = 4e-6;  // E_Y0C: 2 um
  in.covariance(0, 5) = in.covariance(5, 0) = 3e-6;
  in.full_covariance = true;
  const ControllerExport ex = export_kinematics(Controller::linuxcnc, in);
  const ControllerValue& yo = ex.values[3];
  REQUIRE(yo.name == "xyzac-trt-kins.y-offset");
  CHECK(yo.from == "E_Y0A - E_Y0C");
  CHECK(yo.std == Approx(std::sqrt(4e-6 + 4e-6 - 2 * 3e-6)));
}

TEST_CASE("current values are read from the controller's own files and refused by name") {
  const std::string hal =
      "loadrt xyzac-trt-kins\nsetp xyzac-trt-kins.x-rot-point 120.5  # C axis\n"
      "setp xyzac-trt-kins.tool-offset 0\nsetp xyzac-trt-kins.z-offset 35\n";
  const auto cur =
      parse_current_parameters(Controller::linuxcnc, MachineType::AC_trt, hal, "machine.hal");
  CHECK(cur.at("xyzac-trt-kins.x-rot-point") == 120.5);
  CHECK(cur.at("xyzac-trt-kins.z-offset") == 35.0);
  CHECK(cur.count("xyzac-trt-kins.tool-offset") == 0);
  CHECK_THROWS_WITH(parse_current_parameters(Controller::linuxcnc, MachineType::AC_trt,
                                             "setp xyzac-trt-kins.z-offset abc\n", "m.hal"),
                    Catch::Contains("m.hal:1") && Catch::Contains("abc"));
  CHECK_THROWS_WITH(parse_current_parameters(Controller::linuxcnc, MachineType::AC_trt,
                                             "setp xyzac-trt-kins.w-rot-point 1\n", "m.hal"),
                    Catch::Contains("m.hal:1") && Catch::Contains("w-rot-point"));
  const std::string mpf =
      "; toolholder 1\n$TC_CARR23[1]=\"P\"\n$TC_CARR4[1]=1.5 ; l2 x\n$TC_CARR4[2]=9\n"
      "$TC_CARR7[1]=1\n$TC_CARR41[1]=0.01\nM17\n";
  const auto s =
      parse_current_parameters(Controller::siemens, MachineType::AC_trt, mpf, "carr.mpf");
  CHECK(s.at("$TC_CARR4[1]") == 1.5);
  CHECK(s.at("$TC_CARR7[1]") == 1.0);
  CHECK(s.count("$TC_CARR41[1]") == 0);  // fine offsets are not changed
  const std::string json = R"({"controller": "fanuc", "parameters": {"No. 19703": 12.5}})";
  CHECK(parse_current_parameters(Controller::fanuc, MachineType::AC_trt, json, "c.json")
            .at("No. 19703") == 12.5);
  CHECK_THROWS_WITH(
      parse_current_parameters(Controller::siemens, MachineType::AC_trt, json, "c.json"),
      Catch::Contains("fanuc"));
  CHECK_THROWS_AS(parse_controller("okuma"), InvalidArgument);
  // A Siemens axis vector that is not the machine's axis is refused, not "corrected".
  ExportOptions o;
  o.current = {{"$TC_CARR7[1]", 0.0}, {"$TC_CARR9[1]", 1.0}};
  CHECK_THROWS_WITH(export_kinematics(Controller::siemens, ExportInput{}, o),
                    Catch::Contains("v1"));
}

TEST_CASE("free text in the header cannot add a line the controller reads, for every controller") {
  // The model path, the session and date the model names and the time stamp are any text.
  const std::string hostile[] = {"s.csv\nloadusr -w touch X\n",
                                 "s.csv\r\nsetp xyzac-trt-kins.z-offset 500\r",
                                 "s.csv\n$TC_CARR4[1]=500\nM17\n",
                                 "s.csv\ntrafo[0].axis[0].point[0]  5000",
                                 "s.csv\n%\nG0 Z-500",
                                 std::string(2000, 'p') + "loadusr -w touch X"};
  auto lines_of = [](const std::string& text) {
    std::vector<std::string> out;
    std::istringstream in(text);
    for (std::string l; std::getline(in, l);) out.push_back(l);
    return out;
  };
  // The lines a controller reads: all but whole comment lines ('#', or ';' in the MPF).
  auto read_lines = [&](Controller c, const std::string& text) {
    std::vector<std::string> out;
    for (const std::string& l : lines_of(text))
      if (l.empty() || l[0] != (c == Controller::siemens ? ';' : '#')) out.push_back(l);
    return out;
  };
  std::mt19937 rng(5);
  for (MachineType m : {MachineType::AC_trt, MachineType::BC_trt}) {
    ExportInput in = random_identification(m, rng, true);
    ExportOptions o;
    o.generated_at = "2026-01-01T00:00:00Z";
    for (Controller c : {Controller::linuxcnc, Controller::siemens, Controller::isg,
                         Controller::heidenhain, Controller::fanuc}) {
      ExportInput plain = in;
      plain.model_path = "model.json";
      const std::vector<std::string> expected = read_lines(c, export_kinematics(c, plain, o).text);
      for (const std::string& text : hostile) {
        INFO(to_string(c) << ": '" << text.substr(0, 60) << "'");
        ExportInput bad = in;
        bad.source = text;
        bad.model_path = text;
        ExportOptions bad_o = o;
        bad_o.generated_at = text;
        const std::string out = export_kinematics(c, bad, bad_o).text;
        CHECK(read_lines(c, out) == expected);
        CHECK(out.find('\r') == std::string::npos);
        for (const std::string& l : lines_of(out))
          CHECK(l.size() <= 1000);  // halcmd reads 1023 a line
      }
      if (c == Controller::linuxcnc)
        for (const std::string& l : expected)
          CHECK(l.rfind("setp " + std::string(m == MachineType::AC_trt ? "xyzac" : "xyzbc") +
                            "-trt-kins.",
                        0) == 0);
    }
  }
}

// SPDX-License-Identifier: BSD-3-Clause
#include <catch2/catch.hpp>
#include <cctype>
#include <cmath>
#include <map>
#include <sstream>

#include "rotacal/ballbar/nc_program.hpp"
#include "rotacal/io/ballbar_file.hpp"
#include "rotacal/kinematics/machine_description.hpp"

using namespace rotacal;

namespace {

constexpr double kDeg = M_PI / 180.0;

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

bool starts_with(const std::string& s, const std::string& p) { return s.rfind(p, 0) == 0; }
bool contains(const std::string& s, const std::string& p) { return s.find(p) != std::string::npos; }

std::size_t count_prefix(const std::vector<std::string>& lines, const std::string& p) {
  std::size_t n = 0;
  for (const auto& l : lines) n += starts_with(l, p);
  return n;
}

// Value of an address word ("X", "A", ...) in a block; NaN if absent.
double word(const std::string& block, char letter) {
  std::istringstream in(block);
  for (std::string w; in >> w;)
    if (w.size() > 1 && w[0] == letter &&
        (std::isdigit(static_cast<unsigned char>(w[1])) || w[1] == '-' || w[1] == '+' ||
         w[1] == '.'))
      return std::stod(w.substr(1));
  return std::nan("");
}

// Blocks that start with `motion` after the comment line containing `marker`, up to the next
// comment or TCP switch.
std::vector<std::string> blocks_after(const std::vector<std::string>& lines,
                                      const std::string& marker, const std::string& motion) {
  std::vector<std::string> out;
  std::size_t i = 0;
  while (i < lines.size() && !contains(lines[i], marker)) ++i;
  REQUIRE(i < lines.size());
  for (++i; i < lines.size(); ++i) {
    const std::string& l = lines[i];
    if (contains(l, "(") || contains(l, ";")) break;
    if (starts_with(l, motion)) out.push_back(l);
  }
  return out;
}

const char* kTests[] = {"sphere_xy", "sphere_yz", "sphere_zx", "radial_A",
                        "axial_C",   "radial_C",  "axial_A"};

}  // namespace

TEST_CASE("linuxcnc program: machine axes of every test equal ballbar_ac_table2.csv",
          "[ballbar][nc]") {
  const BallbarSession ref = read_ballbar(ROTACAL_SHARED_DIR "/data/ballbar_ac_table2.csv");
  const std::string text = write_nc_program(plan_ballbar_test(BallbarSetup{}), NcDialect::linuxcnc);
  const auto lines = lines_of(text);
  double worst = 0.0;
  for (const char* test : kTests) {
    INFO(test);
    const auto rows = ref.indices_of(test);
    const auto blocks = blocks_after(lines, std::string("(TEST ") + test + ":", "G1 ");
    // A test's first point is reached by the approach or an arc when no block precedes it.
    REQUIRE((blocks.size() == rows.size() || blocks.size() + 1 == rows.size()));
    const std::size_t skip = rows.size() - blocks.size();
    for (std::size_t k = 0; k < blocks.size(); ++k) {
      const BallbarSample& r = ref.samples[rows[k + skip]];
      worst = std::max({worst, std::abs(word(blocks[k], 'X') - r.xyz.x()),
                        std::abs(word(blocks[k], 'Y') - r.xyz.y()),
                        std::abs(word(blocks[k], 'Z') - r.xyz.z()),
                        std::abs(word(blocks[k], 'A') - r.tilt_deg),
                        std::abs(word(blocks[k], 'C') - r.rot_deg)});
    }
  }
  INFO("worst difference " << worst);
  CHECK(worst <= 5.1e-5);  // 4 decimals in the program, 6 in the file
}

TEST_CASE("linuxcnc program structure", "[ballbar][nc]") {
  const std::string text = write_nc_program(plan_ballbar_test(BallbarSetup{}), NcDialect::linuxcnc);
  const auto lines = lines_of(text);
  CHECK(contains(text, "(machine: AC-trt)"));
  CHECK(contains(text, "(ballbar length L0: 100.0000 mm)"));
  CHECK(contains(text, "(pivot: 120.0000, 0.0000, 60.0000 mm"));
  CHECK(contains(text,
                 "(test order: sphere_xy, sphere_yz, sphere_zx, radial_A, axial_C, "
                 "radial_C, axial_A)"));
  CHECK(contains(text, "(kinematics: nominal)"));
  CHECK(count_prefix(lines, "G21 G90 G94") == 1);
  CHECK(count_prefix(lines, "G43 H1") == 1);
  CHECK(count_prefix(lines, "G93") == 1);
  CHECK(count_prefix(lines, "G94") == 1);
  CHECK(count_prefix(lines, "M0") == 1);
  CHECK(lines.back() == "M2");
  CHECK_FALSE(contains(text, "TRAORI"));
  CHECK_FALSE(contains(text, "G43.4"));
  // Linear blocks (see the plan layout test): 359 + 180 + 180 + 89 + 181 + 89 + 360 + 359 +
  // 359 + 358 + 181; arcs: two in XY about +Z, two in ZX about +Y, all G3.
  CHECK(count_prefix(lines, "G1 ") == 2695);
  CHECK(count_prefix(lines, "G17 G3 ") == 2);
  CHECK(count_prefix(lines, "G18 G3 ") == 2);
  CHECK_FALSE(contains(text, " G2 "));
  // First arc: (219.9848, -1.7452) -> (120, 100) about (120, 0); 91 chords of 1 deg at
  // 1000 mm/min: F = 1000 / (91 * 200 sin 0.5 deg) = 6.29632 / min.
  std::string arc;
  for (const auto& l : lines)
    if (starts_with(l, "G17 G3 ")) {
      arc = l;
      break;
    }
  CHECK(arc == "G17 G3 X120.0000 Y100.0000 I-99.9848 J1.7452 F6.2963");
  // sphere_zx (20, 0, 60) -> top of the sphere (120, 0, 160) about (120, 0, 60).
  bool found = false;
  for (const auto& l : lines)
    found = found || l == "G18 G3 X120.0000 Z160.0000 I100.0000 K0.0000 F6.3663";
  CHECK(found);
}

TEST_CASE("heidenhain program: FUNCTION TCPM, table-frame coordinates, CC/C arcs",
          "[ballbar][nc]") {
  const std::string text =
      write_nc_program(plan_ballbar_test(BallbarSetup{}), NcDialect::heidenhain);
  const auto lines = lines_of(text);
  // Block numbers 0, 1, 2, ...
  for (std::size_t i = 0; i < lines.size(); ++i) {
    INFO(lines[i]);
    REQUIRE(starts_with(lines[i], std::to_string(i) + " "));
  }
  std::vector<std::string> blocks;
  for (const auto& l : lines) blocks.push_back(l.substr(l.find(' ') + 1));
  CHECK(blocks.front() == "BEGIN PGM ROTACAL_BALLBAR MM");
  CHECK(blocks.back() == "END PGM ROTACAL_BALLBAR MM");
  CHECK(count_prefix(blocks, "TOOL CALL 1 Z") == 1);
  CHECK(count_prefix(blocks, "STOP") == 1);
  // TCPM on for sphere_xy, sphere_yz, sphere_zx, the A 0 -> -90 move and radial_C; off in the
  // preamble, for the four arcs and at the end.
  CHECK(count_prefix(blocks, "FUNCTION TCPM F CONT AXIS POS PATHCTRL AXIS") == 5);
  CHECK(count_prefix(blocks, "FUNCTION RESET TCPM") == 6);
  CHECK(count_prefix(blocks, "CC ") == 4);
  CHECK(count_prefix(blocks, "C ") == 4);
  CHECK(count_prefix(blocks, "L ") == 2695 + 2);
  CHECK(contains(text, "CC X+120.0000 Z+60.0000\n"));
  CHECK(contains(text, "C X+220.0000 Z+60.0000 DR+ F1000\n"));
  // radial_A under TCPM: the tool stays at (120, 0, 160) on the table while A sweeps.
  const auto ra = blocks_after(blocks, "; TEST radial_A:", "L ");
  REQUIRE(ra.size() == 181);
  for (std::size_t k = 0; k < ra.size(); ++k) {
    INFO(ra[k]);
    CHECK(starts_with(ra[k], "L X+120.0000 Y+0.0000 Z+160.0000 A"));
    CHECK(word(ra[k], 'A') == -90.0 + static_cast<double>(k));
  }
  CHECK(ra.front() == "L X+120.0000 Y+0.0000 Z+160.0000 A-90.0000 C+0.0000 R0 F1000");
}

TEST_CASE("siemens and fanuc programs: TRAORI / G43.4, inverse time", "[ballbar][nc]") {
  const BallbarPlan plan = plan_ballbar_test(BallbarSetup{});
  const auto sie = lines_of(write_nc_program(plan, NcDialect::siemens));
  CHECK(count_prefix(sie, "TRAORI") == 5);
  CHECK(count_prefix(sie, "TRAFOOF") == 6);
  CHECK(count_prefix(sie, "G71 G90 G94") == 1);
  CHECK(count_prefix(sie, "T1 D1") == 1);
  CHECK(count_prefix(sie, "G93") == 1);
  CHECK(count_prefix(sie, "G1 ") == 2695);
  CHECK(count_prefix(sie, "G17 G3 ") + count_prefix(sie, "G18 G3 ") == 4);
  CHECK(sie.back() == "M30");
  const auto ax = blocks_after(sie, "; TEST axial_C:", "G1 ");
  REQUIRE(ax.size() == 360);
  // Tool 120 mm off the C axis: 1 deg chord 240 sin(0.5 deg) mm at 1000 mm/min, F = 477.4709 / min.
  CHECK(ax[90] == "G1 X120.0000 Y0.0000 Z160.0000 A0.0000 C90.0000 F477.4709");

  const std::string fan_text = write_nc_program(plan, NcDialect::fanuc);
  const auto fan = lines_of(fan_text);
  CHECK(fan.front() == "%");
  CHECK(fan.back() == "%");
  CHECK(fan[1] == "O1000 (ROTACAL BALLBAR)");
  CHECK(count_prefix(fan, "G43.4 H1") == 5);
  CHECK(count_prefix(fan, "G43 H1") == 5);  // TCP off keeps the length offset (same group)
  CHECK(count_prefix(fan, "G0 G43 H1 X220.0000 Y0.0000 Z60.0000") == 1);
  CHECK(count_prefix(fan, "G1 ") == 2695);
  for (const auto& l : fan)
    for (char c : l) CHECK_FALSE(std::islower(static_cast<unsigned char>(c)));
  CHECK(contains(fan_text, "(TEST RADIAL_A: 181 SAMPLES)"));
}

TEST_CASE("compensated plan: machine axes compensated, TCP points from nominal kinematics",
          "[ballbar][nc]") {
  Eigen::Matrix<double, 8, 1> v;
  v << 0.0726, -0.0202, 1.1284e-05, -0.000113006, 0.0283, 0.1041, 5.1954e-06, -4.1544e-05;
  const LocationErrors<double> e(v);
  const BallbarPlan plan = plan_ballbar_test(BallbarSetup{}, e);
  const std::string lcnc = write_nc_program(plan, NcDialect::linuxcnc);
  CHECK(contains(lcnc, "(kinematics: COMPENSATED with identified location errors - mm, rad:)"));
  CHECK(contains(lcnc, "(  E_Y0A = 0.0726)"));
  CHECK(contains(lcnc, "(  E_B0C = -4.1544e-05)"));
  // radial_A at A = -90: the compensated command sits where the actual table puts (120, 0, 160).
  const Eigen::Vector3d q(120, 0, 160);
  const Eigen::Vector3d want = forward(MachineType::AC_trt, e, {-90.0 * kDeg, 0.0}, q);
  const auto ra = blocks_after(lines_of(lcnc), "(TEST radial_A:", "G1 ");
  REQUIRE(ra.size() == 181);
  const Eigen::Vector3d got(word(ra[0], 'X'), word(ra[0], 'Y'), word(ra[0], 'Z'));
  CHECK((got - want).cwiseAbs().maxCoeff() <= 5e-5);
  CHECK((got - Eigen::Vector3d(120, 160, 0)).norm() > 0.05);  // differs from the nominal command
  // Heidenhain TCP coordinates: the nominal kinematics, Rx(A) q' = command, solved for q'.
  const auto hh = lines_of(write_nc_program(plan, NcDialect::heidenhain));
  std::vector<std::string> blocks;
  for (const auto& l : hh) blocks.push_back(l.substr(l.find(' ') + 1));
  const auto hra = blocks_after(blocks, "; TEST radial_A:", "L ");
  REQUIRE(hra.size() == 181);
  const Eigen::Vector3d q_tcp =
      Eigen::AngleAxisd(90.0 * kDeg, Eigen::Vector3d::UnitX()).matrix() * want;
  const Eigen::Vector3d got_tcp(word(hra[0], 'X'), word(hra[0], 'Y'), word(hra[0], 'Z'));
  CHECK((got_tcp - q_tcp).cwiseAbs().maxCoeff() <= 5e-5);
  CHECK((got_tcp - q).norm() > 0.05);
}

TEST_CASE("BC-trt programs use B", "[ballbar][nc]") {
  BallbarSetup s;
  s.machine = MachineType::BC_trt;
  s.pivot = Eigen::Vector3d(0.0, 120.0, 60.0);
  const std::string text = write_nc_program(plan_ballbar_test(s), NcDialect::linuxcnc);
  CHECK(contains(text, "(TEST radial_B: 181 samples)"));
  CHECK(contains(text, " B-90.0000 C0.0000 "));
  CHECK_FALSE(contains(text, " A"));
  // radial_B at B = 90: Ry(90) (0, 120, 160) = (160, 120, 0).
  CHECK(contains(text, "G1 X160.0000 Y120.0000 Z0.0000 B90.0000 C0.0000 "));
}

TEST_CASE("options and dialect names", "[ballbar][nc]") {
  BallbarSetup s;
  s.tests = {BallbarTest::sphere_xy};
  const BallbarPlan plan = plan_ballbar_test(s);
  NcProgramOptions o;
  o.decimals = 6;
  o.stop_to_mount = false;
  o.tool = 0;
  const std::string t = write_nc_program(plan, NcDialect::linuxcnc, o);
  CHECK(contains(t, "G1 X219.984770 Y1.745241 Z60.000000 A0.000000 C0.000000 "));
  CHECK_FALSE(contains(t, "\nM0\n"));
  CHECK_FALSE(contains(t, "G43"));
  CHECK_THROWS_AS(write_nc_program(plan, NcDialect::fanuc, o), InvalidArgument);  // tool 0
  o.tool = 1;
  o.decimals = 10;
  CHECK_THROWS_AS(write_nc_program(plan, NcDialect::linuxcnc, o), InvalidArgument);
  o.decimals = 4;
  o.program_name = "TWO WORDS";
  CHECK_THROWS_AS(write_nc_program(plan, NcDialect::heidenhain, o), InvalidArgument);
  CHECK(parse_nc_dialect("siemens") == NcDialect::siemens);
  CHECK(to_string(NcDialect::heidenhain) == "heidenhain");
  CHECK_THROWS_WITH(parse_nc_dialect("mazak"), Catch::Contains("mazak"));
}

TEST_CASE("a hand-made plan with coordinates no machine has, or moves without time, is refused",
          "[ballbar][nc]") {
  BallbarPlan plan = plan_ballbar_test(BallbarSetup{});
  BallbarPlan far = plan;
  far.segments[0].samples[1].xyz.x() = 1e300;
  CHECK_THROWS_WITH(write_nc_program(far, NcDialect::linuxcnc),
                    Catch::Contains("no machine can be sent to"));
  BallbarPlan still = plan;
  still.segments[0].samples[1].time = still.segments[0].samples[0].time;
  CHECK_THROWS_WITH(write_nc_program(still, NcDialect::linuxcnc), Catch::Contains("takes no time"));
}

namespace {

// A line of `d` that is a whole comment ("N " block numbers of heidenhain taken off).
bool is_comment(NcDialect d, const std::string& l) {
  if (d == NcDialect::linuxcnc || d == NcDialect::fanuc)
    return l.size() >= 2 && l.front() == '(' && l.back() == ')' &&
           l.find_first_of("()", 1) == l.size() - 1;
  return starts_with(l, ";");
}

// The blocks of a program that are not comments, in order.
std::vector<std::string> blocks(NcDialect d, const std::string& text) {
  std::vector<std::string> out;
  for (std::string l : lines_of(text)) {
    if (d == NcDialect::heidenhain && !l.empty() &&
        std::isdigit(static_cast<unsigned char>(l[0])))  // block number
      l = l.substr(l.find(' ') + 1);
    if (!is_comment(d, l)) out.push_back(l);
  }
  return out;
}

MachineType renamed(MachineType m, const std::string& name) {
  MachineDescription d = m.description();
  d.name = name;
  return MachineType::from_description(d);
}

}  // namespace

TEST_CASE("a machine's name cannot add a block to the program, in any dialect", "[ballbar][nc]") {
  // The name is free text from a description file; it is written in the header comments.
  const std::string hostile[] = {"x\nG0 Z-500\n",           "x\r\nG0 Z-500\r\n",
                                 "x) G0 Z-500 (",           "x; G0 Z-500",
                                 "%\nG0 Z-500\n%",          "MSG, G0 Z-500",
                                 "\n$TC_CARR4[1]=500\nM30", std::string(400, 'n') + "\nG0 Z-500"};
  for (MachineType base : {MachineType::AC_trt, MachineType::BC_trt}) {
    BallbarSetup s;
    s.tests = {BallbarTest::sphere_xy, BallbarTest::radial_c};
    s.machine = renamed(base, "plain");
    if (base == MachineType::BC_trt) s.pivot = Eigen::Vector3d(0.0, 120.0, 60.0);
    const BallbarPlan plain = plan_ballbar_test(s);
    for (const std::string& name : hostile) {
      s.machine = renamed(base, name);
      const BallbarPlan plan = plan_ballbar_test(s);
      for (NcDialect d :
           {NcDialect::linuxcnc, NcDialect::heidenhain, NcDialect::siemens, NcDialect::fanuc}) {
        INFO(to_string(d) << ", machine named '" << name << "'");
        const std::string text = write_nc_program(plan, d);
        // The same blocks as for a plain name, every other line a whole comment.
        CHECK(blocks(d, text) == blocks(d, write_nc_program(plain, d)));
        CHECK_FALSE(contains(text, "\r"));
      }
    }
  }
}

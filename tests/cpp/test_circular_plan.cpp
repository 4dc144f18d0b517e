// SPDX-License-Identifier: BSD-3-Clause
#include <catch2/catch.hpp>
#include <cctype>
#include <cmath>
#include <map>
#include <regex>
#include <sstream>

#include "rotacal/circular/plan.hpp"
#include "rotacal/core/error.hpp"
#include "rotacal/io/ballbar_file.hpp"
#include "rotacal/kinematics/machine_description.hpp"

using namespace rotacal;

namespace {

// Message of the InvalidArgument that f throws (fails the test if it throws none).
template <typename F>
std::string message_of(F f) {
  try {
    f();
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  FAIL("no InvalidArgument thrown");
  return {};
}

}  // namespace

TEST_CASE("Circular plan: runs, labels, timing and geometry from the options", "[circular]") {
  CircularTestPlan p;
  p.radius = 150.0;
  p.centre = Eigen::Vector3d(10.0, -20.0, 30.0);
  p.planes = {CircularPlane::XY, CircularPlane::ZX};
  p.feeds_mm_per_min = {1200.0, 3000.0};
  p.span_deg = 220.0;
  p.start_deg = -20.0;
  p.sample_rate_hz = 100.0;
  const CircularPlanResult r = plan_circular_test(p);
  REQUIRE(r.runs.size() == 8);  // planes x feeds x directions
  CHECK(r.runs[0].label == "circular_XY_ccw_f1200");
  CHECK(r.runs[1].label == "circular_XY_cw_f1200");
  CHECK(r.runs[2].label == "circular_XY_ccw_f3000");
  CHECK(r.runs[7].label == "circular_ZX_cw_f3000");
  for (const CircularRun& run : r.runs) {
    // Data arc duration = arc length / feed; readings at the sample rate.
    const double duration = 220.0 * M_PI / 180.0 * 150.0 / (run.feed_mm_per_min / 60.0);
    CHECK(run.time.size() == static_cast<std::size_t>(std::floor(duration * 100.0 + 1e-9)) + 1);
    CHECK(run.time[1] - run.time[0] == Approx(0.01));
    const double sense = run.direction == CircularDirection::ccw ? 1.0 : -1.0;
    CHECK(run.angle_deg.front() == Approx(run.direction == CircularDirection::ccw ? -20.0 : 200.0));
    CHECK(sense * (run.angle_deg.back() - run.angle_deg.front()) <= 220.0 + 1e-9);
    CHECK(sense * (run.angle_deg.back() - run.angle_deg.front()) >
          220.0 - 360.0 * run.feed_mm_per_min / 60.0 / 150.0 / (2 * M_PI) / 100.0 * 1.01);
    // Run-in: the data arc starts run_in_deg after the run-in start, at the feed.
    CHECK(run.time[0] - run.t_start ==
          Approx(45.0 * M_PI / 180.0 * 150.0 / (run.feed_mm_per_min / 60.0)));
    CHECK(run.angle_at(run.time[5]) == Approx(run.angle_deg[5]));
  }
  // Time never goes back across runs.
  for (std::size_t k = 1; k < r.runs.size(); ++k)
    CHECK(r.runs[k].t_start > r.runs[k - 1].time.back());
  // ZX: theta from +Z towards +X.
  const Eigen::Vector3d q = circular_point(p, CircularPlane::ZX, 90.0);
  CHECK((q - Eigen::Vector3d(10.0 + 150.0, -20.0, 30.0)).norm() < 1e-12);
  const BallbarSession s = circular_commanded_session(r);
  CHECK(s.samples.size() == r.num_samples());
  CHECK(s.ballbar_length == 150.0);
  CHECK(s.tests().size() == 8);
  for (const BallbarSample& b : s.samples)
    CHECK(((b.xyz - p.centre).norm() - 150.0) == Approx(0.0).margin(1e-9));
}

TEST_CASE("Circular plan: one feed gives labels without a feed suffix; the session round-trips",
          "[circular]") {
  CircularTestPlan p;
  p.planes = {CircularPlane::YZ};
  p.feeds_mm_per_min = {2000.0};
  p.sample_rate_hz = 50.0;
  const CircularPlanResult r = plan_circular_test(p);
  REQUIRE(r.runs.size() == 2);
  CHECK(r.runs[0].label == "circular_YZ_ccw");
  CHECK(r.runs[1].label == "circular_YZ_cw");
  const BallbarSession s = circular_commanded_session(r);
  std::istringstream in(format_ballbar(s));
  const BallbarSession back = parse_ballbar(in, "circular.csv");
  CHECK(back.tests() == s.tests());
  CHECK(back.samples.size() == s.samples.size());
}

TEST_CASE("Circular plan: bad options are refused naming the option", "[circular]") {
  const auto with = [](auto change) {
    CircularTestPlan p;
    change(p);
    return message_of([&] { plan_circular_test(p); });
  };
  CHECK_THAT(with([](CircularTestPlan& p) { p.planes.clear(); }), Catch::Contains("planes"));
  CHECK_THAT(with([](CircularTestPlan& p) { p.planes = {CircularPlane::XY, CircularPlane::XY}; }),
             Catch::Contains("planes: a plane is repeated"));
  CHECK_THAT(with([](CircularTestPlan& p) { p.feeds_mm_per_min = {1000.0, -5.0}; }),
             Catch::Contains("feeds_mm_per_min"));
  CHECK_THAT(with([](CircularTestPlan& p) { p.feeds_mm_per_min.clear(); }),
             Catch::Contains("feeds_mm_per_min"));
  CHECK_THAT(with([](CircularTestPlan& p) { p.feeds_mm_per_min = {1000.0, 1000.0}; }),
             Catch::Contains("feeds_mm_per_min"));
  CHECK_THAT(with([](CircularTestPlan& p) { p.directions.clear(); }),
             Catch::Contains("directions"));
  CHECK_THAT(with([](CircularTestPlan& p) {
               p.directions = {CircularDirection::cw, CircularDirection::cw};
             }),
             Catch::Contains("directions"));
  CHECK_THAT(with([](CircularTestPlan& p) { p.span_deg = 400.0; }), Catch::Contains("span_deg"));
  CHECK_THAT(with([](CircularTestPlan& p) { p.radius = 0.0; }), Catch::Contains("radius"));
  CHECK_THAT(with([](CircularTestPlan& p) { p.radius = NAN; }), Catch::Contains("radius"));
  CHECK_THAT(with([](CircularTestPlan& p) { p.run_in_deg = -1.0; }), Catch::Contains("run_in_deg"));
  CHECK_THAT(with([](CircularTestPlan& p) { p.sample_rate_hz = 0.0; }),
             Catch::Contains("sample_rate_hz"));
  // Too fast for the sample rate: fewer than 36 readings over the arc.
  CHECK_THAT(with([](CircularTestPlan& p) {
               p.feeds_mm_per_min = {60000.0};
               p.sample_rate_hz = 1.0;
             }),
             Catch::Contains("feeds_mm_per_min"));
  CHECK_THAT(message_of([] { parse_circular_plane("XZ"); }),
             Catch::Contains("plane") && Catch::Contains("XZ"));
  CHECK_THAT(message_of([] { parse_circular_direction("up"); }), Catch::Contains("direction"));
  CHECK(parse_circular_plane("zx") == CircularPlane::ZX);
}

TEST_CASE("Circular NC program: G2/G3 arcs in G17/G18/G19 that stay on the circle", "[circular]") {
  CircularTestPlan p;
  p.radius = 100.0;
  p.centre = Eigen::Vector3d(120.0, 0.0, 60.0);
  p.feeds_mm_per_min = {1000.0};
  p.span_deg = 360.0;
  const CircularPlanResult r = plan_circular_test(p);
  const std::string nc = write_circular_nc_program(r, NcDialect::linuxcnc);
  // Every arc block: its end point on the circle, and the centre (start + I J K) at the pivot.
  const std::regex arc(
      R"((G17|G18|G19) (G2|G3) ([XYZ])(-?[0-9.]+) ([XYZ])(-?[0-9.]+) ([IJK])(-?[0-9.]+) ([IJK])(-?[0-9.]+) F([0-9.]+))");
  std::istringstream lines(nc);
  std::string line;
  int arcs = 0, g3 = 0, g2 = 0;
  std::map<std::string, int> planes;
  Eigen::Vector3d cur(0, 0, 0);
  bool have = false;
  const std::regex rapid(R"(G0 X(-?[0-9.]+) Y(-?[0-9.]+) Z(-?[0-9.]+))");
  while (std::getline(lines, line)) {
    std::smatch m;
    if (std::regex_search(line, m, rapid)) {
      cur = Eigen::Vector3d(std::stod(m[1]), std::stod(m[2]), std::stod(m[3]));
      have = true;
      continue;
    }
    if (!std::regex_search(line, m, arc)) continue;
    REQUIRE(have);
    ++arcs;
    (m[2] == "G3" ? g3 : g2)++;
    planes[m[1]]++;
    Eigen::Vector3d end = cur, centre = cur;
    end[m[3].str()[0] - 'X'] = std::stod(m[4]);
    end[m[5].str()[0] - 'X'] = std::stod(m[6]);
    centre[m[7].str()[0] - 'I'] += std::stod(m[8]);
    centre[m[9].str()[0] - 'I'] += std::stod(m[10]);
    CHECK((centre - p.centre).norm() < 1e-3);
    CHECK((end - p.centre).norm() == Approx(100.0).margin(1e-3));
    CHECK(std::stod(m[11]) == Approx(1000.0));
    cur = end;
  }
  // Per plane and direction: 45 + 360 + 45 deg in blocks of at most 90 deg: 5 blocks each,
  // plus the move along the circle between the two runs of a plane.
  CHECK(planes["G17"] >= 10);
  CHECK(planes["G18"] >= 10);
  CHECK(planes["G19"] >= 10);
  CHECK(g3 >= 15);
  CHECK(g2 >= 15);
  CHECK(arcs == planes["G17"] + planes["G18"] + planes["G19"]);
  for (NcDialect d : {NcDialect::heidenhain, NcDialect::siemens, NcDialect::fanuc}) {
    const std::string t = write_circular_nc_program(r, d);
    CHECK(!t.empty());
    if (d == NcDialect::heidenhain) {
      CHECK_THAT(t, Catch::Contains("CC X+120.0000 Y+0.0000"));
      CHECK_THAT(t, Catch::Contains("DR+"));
      CHECK_THAT(t, Catch::Contains("DR-"));
    } else {
      CHECK_THAT(t, Catch::Contains("G18 G3"));
    }
  }
  NcProgramOptions bad;
  bad.decimals = 12;
  CHECK_THAT(message_of([&] { write_circular_nc_program(r, NcDialect::linuxcnc, bad); }),
             Catch::Contains("decimals"));
}

TEST_CASE("Circular NC program: a machine's name cannot add a block, in any dialect",
          "[circular]") {
  // The name is free text from a description file; it is written in the header comments.
  auto lines_of = [](const std::string& text) {
    std::vector<std::string> out;
    std::istringstream in(text);
    for (std::string l; std::getline(in, l);) out.push_back(l);
    return out;
  };
  auto blocks = [&](NcDialect d,
                    const std::string& text) {  // the lines that are not whole comments
    std::vector<std::string> out;
    for (std::string l : lines_of(text)) {
      if (d == NcDialect::heidenhain && !l.empty() &&
          std::isdigit(static_cast<unsigned char>(l[0])))  // block number
        l = l.substr(l.find(' ') + 1);
      const bool comment =
          d == NcDialect::linuxcnc || d == NcDialect::fanuc
              ? l.size() >= 2 && l.front() == '(' && l.find_first_of("()", 1) == l.size() - 1
              : l.rfind(";", 0) == 0;
      if (!comment) out.push_back(l);
    }
    return out;
  };
  auto named = [](const std::string& name) {
    MachineDescription d = MachineType::AC_trt.description();
    d.name = name;
    CircularTestPlan p;
    p.machine = MachineType::from_description(d);
    p.planes = {CircularPlane::XY};
    p.feeds_mm_per_min = {1000.0};
    return plan_circular_test(p);
  };
  const CircularPlanResult plain = named("plain");
  for (const std::string& name :
       {std::string("x\nG0 Z-500\n"), std::string("x\rM30\r"), std::string("x) G0 Z-500 ("),
        std::string("x; G0 Z-500"), std::string("%\nG0 Z-500\n%"), std::string("MSG, x"),
        std::string(300, 'n') + "\nG0 Z-500"}) {
    const CircularPlanResult r = named(name);
    for (NcDialect d :
         {NcDialect::linuxcnc, NcDialect::heidenhain, NcDialect::siemens, NcDialect::fanuc}) {
      INFO(to_string(d) << ", machine named '" << name << "'");
      const std::string text = write_circular_nc_program(r, d);
      CHECK(blocks(d, text) == blocks(d, write_circular_nc_program(plain, d)));
      CHECK(text.find('\r') == std::string::npos);
    }
  }
}

// SPDX-License-Identifier: BSD-3-Clause
#include <catch2/catch.hpp>
#include <cmath>
#include <map>
#include <sstream>

#include "rotacal/ballbar/plan.hpp"
#include "rotacal/io/ballbar_file.hpp"

using namespace rotacal;

namespace {

constexpr double kDeg = M_PI / 180.0;

Eigen::Matrix3d Rx(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).matrix(); }
Eigen::Matrix3d Ry(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).matrix(); }
Eigen::Matrix3d Rz(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).matrix(); }

// Nominal machine position of a table point, written out independently of machine.hpp
// (formats.md: Rx(A) Rz(C) q for AC-trt, Ry(B) Rz(C) q for BC-trt).
Eigen::Vector3d nominal_machine(MachineType m, double tilt_deg, double rot_deg,
                                const Eigen::Vector3d& q) {
  const Eigen::Matrix3d T = m == MachineType::AC_trt ? Rx(tilt_deg * kDeg) : Ry(tilt_deg * kDeg);
  return T * Rz(rot_deg * kDeg) * q;
}

const PlanSegment& segment_of(const BallbarPlan& plan, const std::string& label) {
  for (const auto& s : plan.segments)
    if (s.label == label) return s;
  FAIL("no segment " << label);
  return plan.segments.front();
}

// Flynn Sec. 3.2 Table 2 errors (shared/data/ballbar_ac_table2.truth.json), ISO order.
LocationErrors<double> table2_errors() {
  Eigen::Matrix<double, 8, 1> v;
  v << 0.0726, -0.0202, 1.1284e-05, -0.000113006, 0.0283, 0.1041, 5.1954e-06, -4.1544e-05;
  return LocationErrors<double>(v);
}

}  // namespace

TEST_CASE("default AC-trt plan reproduces the commanded rows of ballbar_ac_table2.csv",
          "[ballbar][plan]") {
  const BallbarSession ref = read_ballbar(ROTACAL_SHARED_DIR "/data/ballbar_ac_table2.csv");
  const BallbarPlan plan = plan_ballbar_test(BallbarSetup{});
  REQUIRE(ref.machine == MachineType::AC_trt);
  CHECK(ref.ballbar_length == plan.setup.ballbar_length);
  CHECK((ref.pivot - plan.setup.pivot).norm() == 0.0);

  // Same tests in the same order.
  std::vector<std::string> planned;
  for (const auto& s : plan.segments)
    if (s.kind == SegmentKind::test) planned.push_back(s.label);
  CHECK(planned == ref.tests());

  double worst_xyz = 0.0, worst_angle = 0.0;
  for (const std::string& label : ref.tests()) {
    const auto rows = ref.indices_of(label);
    const PlanSegment& seg = segment_of(plan, label);
    INFO(label);
    REQUIRE(seg.samples.size() == rows.size());
    for (std::size_t k = 0; k < rows.size(); ++k) {
      const BallbarSample& r = ref.samples[rows[k]];
      const PlannedSample& s = seg.samples[k];
      worst_xyz = std::max(worst_xyz, (s.xyz - r.xyz).cwiseAbs().maxCoeff());
      worst_angle = std::max(
          {worst_angle, std::abs(s.tilt_deg - r.tilt_deg), std::abs(s.rot_deg - r.rot_deg)});
    }
  }
  INFO("worst X,Y,Z difference " << worst_xyz << " mm, worst angle " << worst_angle << " deg");
  // The file carries 6 decimals: 5e-7 mm rounding.
  CHECK(worst_xyz <= 5.0000001e-7);
  CHECK(worst_angle == 0.0);
}

TEST_CASE("every sample, tests and transitions, keeps the ballbar at L0", "[ballbar][plan]") {
  for (MachineType m : {MachineType::AC_trt, MachineType::BC_trt}) {
    for (RadialSide side : {RadialSide::outside, RadialSide::inside}) {
      BallbarSetup s;
      s.machine = m;
      s.radial_c_side = side;
      s.pivot = Eigen::Vector3d(110.0, -35.0, 70.0);  // off every principal plane
      s.ballbar_length = 150.0;
      s.step_deg = 2.5;
      const BallbarPlan plan = plan_ballbar_test(s);
      double worst_table = 0.0, worst_machine = 0.0;
      std::size_t n = 0;
      for (const auto& seg : plan.segments) {
        for (const auto& p : seg.samples) {
          worst_table = std::max(worst_table, std::abs((p.p_table - s.pivot).norm() - 150.0));
          const Eigen::Vector3d pivot_m = nominal_machine(m, p.tilt_deg, p.rot_deg, s.pivot);
          worst_machine = std::max(worst_machine, std::abs((p.xyz - pivot_m).norm() - 150.0));
          ++n;
        }
      }
      INFO(to_string(m) << " " << to_string(side) << ": " << n << " samples");
      CHECK(worst_table < 1e-9);
      CHECK(worst_machine < 1e-9);
    }
  }
}

TEST_CASE("default plan layout: segments, transitions and arcs as derived by hand",
          "[ballbar][plan]") {
  const BallbarPlan plan = plan_ballbar_test(BallbarSetup{});
  struct Expect {
    std::string label;
    SegmentKind kind;
    std::size_t samples;
  };
  const auto T = SegmentKind::test, R = SegmentKind::rotary_transition,
             A = SegmentKind::arc_transition;
  // sphere_xy ends at 359 deg, sphere_yz starts at 90 deg on the XY circle: 91 deg arc, 90
  // points between. radial_A starts at A = -90: arc to the top at rotary zero (end kept, as
  // the rotary move starts there), A 0 -> -90 (89 between). axial_C -> radial_C: C 359 -> 0 at
  // the axial_C point (end kept), arc to (220, 0, 60). radial_C and axial_A share the tool
  // point: one rotary move C 359 -> 0 with A 0 -> -90 (359 steps, 358 between).
  const std::vector<Expect> expect = {
      {"sphere_xy", T, 360}, {"transition", A, 90},  {"sphere_yz", T, 181},  {"transition", A, 89},
      {"sphere_zx", T, 181}, {"transition", A, 90},  {"transition", R, 89},  {"radial_A", T, 181},
      {"transition", R, 89}, {"axial_C", T, 360},    {"transition", R, 359}, {"transition", A, 89},
      {"radial_C", T, 360},  {"transition", R, 358}, {"axial_A", T, 181}};
  REQUIRE(plan.segments.size() == expect.size());
  for (std::size_t i = 0; i < expect.size(); ++i) {
    INFO("segment " << i);
    CHECK(plan.segments[i].label == expect[i].label);
    CHECK(plan.segments[i].kind == expect[i].kind);
    CHECK(plan.segments[i].samples.size() == expect[i].samples);
  }
  // Arcs: XY plane turning about +Z (91 and 90 deg), ZX plane about +Y (90 deg twice).
  const std::vector<std::pair<std::size_t, std::pair<int, double>>> arcs = {
      {1, {2, 91.0}}, {3, {2, 90.0}}, {5, {1, 90.0}}, {11, {1, 90.0}}};
  for (const auto& [i, pa] : arcs) {
    const TransitionArc& a = plan.segments[i].arc;
    INFO("arc segment " << i);
    CHECK(a.principal_axis == pa.first);
    CHECK(a.axis[pa.first] == 1.0);
    CHECK(std::abs(a.angle / kDeg - pa.second) < 1e-9);
    // It starts at the previous sample and ends at the first sample of the next test.
    CHECK((a.start - plan.segments[i - 1].samples.back().p_table).norm() < 1e-12);
  }
  CHECK((plan.segments[5].arc.start - Eigen::Vector3d(20, 0, 60)).norm() < 1e-12);
  CHECK((plan.segments[5].arc.end - Eigen::Vector3d(120, 0, 160)).norm() < 1e-12);
  CHECK((plan.segments[11].arc.end - Eigen::Vector3d(220, 0, 60)).norm() < 1e-12);
  // Rotary transition into radial_A: tool fixed at (120, 0, 160) in the table, A 0 -> -90.
  const PlanSegment& r = plan.segments[6];
  CHECK(r.samples.front().tilt_deg == -1.0);
  CHECK(r.samples.back().tilt_deg == -89.0);
  for (const auto& p : r.samples) CHECK((p.p_table - Eigen::Vector3d(120, 0, 160)).norm() == 0.0);
  // Consecutive points of every transition are at most one step apart (1 deg).
  double worst_step = 0.0;
  const PlannedSample* prev = nullptr;
  for (const auto& seg : plan.segments) {
    for (const auto& p : seg.samples) {
      if (prev && seg.kind != SegmentKind::test) {
        const double turn =
            std::acos(std::min(1.0, (prev->p_table - plan.setup.pivot)
                                        .normalized()
                                        .dot((p.p_table - plan.setup.pivot).normalized())));
        worst_step = std::max({worst_step, turn / kDeg, std::abs(p.tilt_deg - prev->tilt_deg),
                               std::abs(p.rot_deg - prev->rot_deg)});
      }
      prev = &p;
    }
  }
  CHECK(worst_step <= 1.0 + 1e-9);
}

TEST_CASE("time stamps follow the feeds", "[ballbar][plan]") {
  BallbarSetup s;
  const BallbarPlan plan = plan_ballbar_test(s);
  const PlanSegment& xy = segment_of(plan, "sphere_xy");
  // Chord of 1 deg on a 100 mm circle at 1000 mm/min.
  const double chord = 2.0 * 100.0 * std::sin(0.5 * kDeg);
  CHECK(xy.samples[0].time == 0.0);
  CHECK(std::abs(xy.samples[1].time - 60.0 * chord / 1000.0) < 1e-12);
  double prev = -1.0;
  bool increasing = true;
  for (const auto& seg : plan.segments)
    for (const auto& p : seg.samples) {
      increasing = increasing && p.time > prev;
      prev = p.time;
    }
  CHECK(increasing);
  CHECK(plan.duration() == prev);

  // A tool point on the C axis does not move: the rotary feed sets the pace (1 deg at
  // 3600 deg/min = 1/60 s).
  s.tests = {BallbarTest::radial_c};
  s.radial_c_side = RadialSide::inside;
  s.pivot = Eigen::Vector3d(100.0, 0.0, 60.0);
  const BallbarPlan on_axis = plan_ballbar_test(s);
  const auto& c = on_axis.segments.at(0).samples;
  CHECK((c[0].xyz - Eigen::Vector3d(0, 0, 60)).norm() < 1e-12);
  CHECK(std::abs(c[5].time - 5.0 / 60.0) < 1e-12);
}

TEST_CASE("BC-trt plan: radial_B / axial_B about the B axis", "[ballbar][plan]") {
  BallbarSetup s;
  s.machine = MachineType::BC_trt;
  s.pivot = Eigen::Vector3d(0.0, 120.0, 60.0);
  const BallbarPlan plan = plan_ballbar_test(s);
  std::vector<std::string> labels;
  for (const auto& seg : plan.segments)
    if (seg.kind == SegmentKind::test) labels.push_back(seg.label);
  CHECK(labels == std::vector<std::string>{"sphere_xy", "sphere_yz", "sphere_zx", "radial_B",
                                           "axial_C", "radial_C", "axial_B"});
  // radial_B: the pivot is 60 mm above the B axis (Y): tool at (0, 120, 160); at B = 90 deg,
  // Ry(90) (x, y, z) = (z, y, -x) = (160, 120, 0).
  const PlanSegment& rb = segment_of(plan, "radial_B");
  CHECK((rb.samples.front().p_table - Eigen::Vector3d(0, 120, 160)).norm() < 1e-12);
  CHECK(rb.samples.back().tilt_deg == 90.0);
  CHECK((rb.samples.back().xyz - Eigen::Vector3d(160, 120, 0)).norm() < 1e-12);
  // axial_B along +Y, radial_C outward from the C axis (also +Y here).
  CHECK((segment_of(plan, "axial_B").samples[0].p_table - Eigen::Vector3d(0, 220, 60)).norm() <
        1e-12);
  CHECK((segment_of(plan, "radial_C").samples[0].p_table - Eigen::Vector3d(0, 220, 60)).norm() <
        1e-12);
  // C = 90: Rz(90) (0, 220, 60) = (-220, 0, 60).
  CHECK((segment_of(plan, "radial_C").samples[90].xyz - Eigen::Vector3d(-220, 0, 60)).norm() <
        1e-12);
}

TEST_CASE("radial C inside and outside the pivot circle (Flynn's +-L0)", "[ballbar][plan]") {
  BallbarSetup s;
  s.tests = {BallbarTest::radial_c};
  s.radial_c_side = RadialSide::inside;
  CHECK((plan_ballbar_test(s).segments[0].samples[0].p_table - Eigen::Vector3d(20, 0, 60)).norm() <
        1e-12);
  s.radial_c_side = RadialSide::outside;
  CHECK((plan_ballbar_test(s).segments[0].samples[0].p_table - Eigen::Vector3d(220, 0, 60)).norm() <
        1e-12);
  CHECK(parse_radial_side("-") == RadialSide::inside);
  CHECK(parse_radial_side("outside") == RadialSide::outside);
  CHECK_THROWS_AS(parse_radial_side("left"), InvalidArgument);
}

TEST_CASE("compensated plan: identified == actual puts the tool on its table-frame target",
          "[ballbar][plan]") {
  const LocationErrors<double> actual = table2_errors();
  const MachineType m = MachineType::AC_trt;
  const BallbarPlan nominal = plan_ballbar_test(BallbarSetup{});
  const BallbarPlan compensated = plan_ballbar_test(BallbarSetup{}, actual);
  LocationErrors<double> half = actual;
  half.v *= 0.5;
  const BallbarPlan partly = plan_ballbar_test(BallbarSetup{}, half);
  REQUIRE(compensated.compensation.has_value());
  CHECK_FALSE(nominal.compensation.has_value());

  // Where the tool is relative to the (actual) table: table_pose^-1 * xyz.
  auto worst_miss = [&](const BallbarPlan& plan) {
    double w = 0.0;
    for (const auto& seg : plan.segments)
      for (const auto& p : seg.samples) {
        const Eigen::Vector3d on_table = forward(m, actual, p.angles_rad(), p.p_table);
        w = std::max(w, (on_table - p.xyz).norm());
      }
    return w;
  };
  const double miss_comp = worst_miss(compensated);
  const double miss_nominal = worst_miss(nominal);
  const double miss_half = worst_miss(partly);
  INFO("worst miss: compensated " << miss_comp << " mm, half " << miss_half << " mm, nominal "
                                  << miss_nominal << " mm");
  CHECK(miss_comp < 1e-9);
  CHECK(miss_nominal > 0.05);  // Table 2 errors: ~0.1 mm offsets, ~1e-4 rad tilts at ~200 mm
  CHECK(std::abs(miss_half / miss_nominal - 0.5) < 0.01);
  // Same toolpath: table-frame targets and angles unchanged; at rotary zero the command is
  // the target itself whatever the errors (rotations by 0).
  const auto& a = nominal.segments;
  const auto& b = compensated.segments;
  REQUIRE(a.size() == b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    REQUIRE(a[i].samples.size() == b[i].samples.size());
    for (std::size_t k = 0; k < a[i].samples.size(); ++k) {
      CHECK(a[i].samples[k].p_table == b[i].samples[k].p_table);
      CHECK(a[i].samples[k].tilt_deg == b[i].samples[k].tilt_deg);
      if (b[i].samples[k].tilt_deg == 0.0 && b[i].samples[k].rot_deg == 0.0)
        CHECK(b[i].samples[k].xyz == b[i].samples[k].p_table);
    }
  }
}

TEST_CASE("sweeps: full turns drop the repeated end, off-grid ends are kept", "[ballbar][plan]") {
  BallbarSetup s;
  s.step_deg = 2.0;
  s.tests = {BallbarTest::sphere_xy, BallbarTest::axial_c};
  BallbarPlan p = plan_ballbar_test(s);
  CHECK(segment_of(p, "sphere_xy").samples.size() == 180);
  CHECK(segment_of(p, "axial_C").samples.back().rot_deg == 358.0);
  s.step_deg = 7.0;
  s.tests = {BallbarTest::radial_tilt, BallbarTest::sphere_yz};
  p = plan_ballbar_test(s);
  const auto& ra = segment_of(p, "radial_A").samples;
  REQUIRE(ra.size() == 27);  // -90, -83, ..., 85 and then 90
  CHECK(ra[25].tilt_deg == 85.0);
  CHECK(ra[26].tilt_deg == 90.0);
  CHECK(segment_of(p, "sphere_yz").samples.size() == 27);  // 0, 7, ..., 175, 180
  s.rot_range_deg = {-45.0, 45.0};
  s.step_deg = 1.0;
  s.tests = {BallbarTest::radial_c};
  CHECK(plan_ballbar_test(s).segments[0].samples.size() == 91);
}

TEST_CASE("bad setups are refused with the option named", "[ballbar][plan]") {
  auto refused = [](const BallbarSetup& s, const std::string& word) {
    try {
      plan_ballbar_test(s);
    } catch (const InvalidArgument& e) {
      return std::string(e.what()).find(word) != std::string::npos;
    }
    return false;
  };
  BallbarSetup s;
  s.ballbar_length = 0.0;
  CHECK(refused(s, "ballbar_length"));
  s = {};
  s.step_deg = -1.0;
  CHECK(refused(s, "step_deg"));
  s = {};
  s.feed_mm_per_min = std::nan("");
  CHECK(refused(s, "feed_mm_per_min"));
  s = {};
  s.tilt_range_deg = {30.0, -30.0};
  CHECK(refused(s, "tilt_range_deg"));
  s = {};
  s.rot_range_deg = {0.0, 720.0};
  CHECK(refused(s, "rot_range_deg"));
  s = {};
  s.tests = {};
  CHECK(refused(s, "tests"));
  s = {};
  s.tests = {BallbarTest::radial_c, BallbarTest::radial_c};
  CHECK(refused(s, "radial_C"));
  s = {};
  s.pivot = Eigen::Vector3d(0.0, 0.0, 60.0);  // on the C axis: no radial direction for C
  CHECK(refused(s, "radial_C"));
  s.tests = {BallbarTest::sphere_xy, BallbarTest::radial_tilt};
  CHECK_NOTHROW(plan_ballbar_test(s));         // radial_A is fine: 60 mm above the A axis
  s.pivot = Eigen::Vector3d(120.0, 0.0, 0.0);  // on the A axis
  CHECK(refused(s, "radial_A"));
  LocationErrors<double> bad;
  bad.v[3] = std::nan("");
  CHECK_THROWS_AS(plan_ballbar_test(BallbarSetup{}, bad), InvalidArgument);
  // Huge finite values (issue 17 item 10: an internal error in the NC writer before): refused
  // with the command-line option named.
  s = {};
  s.ballbar_length = 1e300;
  CHECK(refused(s, "--length"));
  s = {};
  s.ballbar_length = 1e9;  // a 72-year program at the default feeds
  CHECK(refused(s, "--length"));
  s = {};
  s.pivot = Eigen::Vector3d(1e300, 0.0, 60.0);
  CHECK(refused(s, "--pivot"));
  s = {};
  s.step_deg = -1.0;
  CHECK(refused(s, "--step"));
  s = {};
  s.feed_mm_per_min = 1e300;
  CHECK(refused(s, "--feed"));
  // A program longer than a day (slow feeds) is refused, naming the cause.
  s = {};
  s.feed_deg_per_min = 1e-3;
  CHECK(refused(s, "more than 24 h"));
}

TEST_CASE("test labels parse per machine", "[ballbar][plan]") {
  CHECK(test_label(BallbarTest::radial_tilt, MachineType::AC_trt) == "radial_A");
  CHECK(test_label(BallbarTest::axial_tilt, MachineType::BC_trt) == "axial_B");
  CHECK(parse_ballbar_test("axial_C", MachineType::BC_trt) == BallbarTest::axial_c);
  CHECK(parse_ballbar_test("radial_B", MachineType::BC_trt) == BallbarTest::radial_tilt);
  CHECK_THROWS_WITH(parse_ballbar_test("radial_B", MachineType::AC_trt),
                    Catch::Contains("radial_B") && Catch::Contains("radial_A"));
}

TEST_CASE("tabulate and commanded_session flatten the plan in order", "[ballbar][plan]") {
  const BallbarPlan plan = plan_ballbar_test(BallbarSetup{});
  const PlanTable t = tabulate(plan);
  const auto n = static_cast<Eigen::Index>(plan.num_samples());
  REQUIRE(t.time.size() == n);
  REQUIRE(static_cast<Eigen::Index>(t.labels.size()) == n);
  CHECK(t.labels.front() == "sphere_xy");
  CHECK(t.labels.back() == "axial_A");
  // Last row: axial_A at A = 90: Rx(90) (220, 0, 60) = (220, -60, 0).
  CHECK((t.machine_axes.row(n - 1) - Eigen::Matrix<double, 1, 5>(220, -60, 0, 90, 0)).norm() <
        1e-12);
  CHECK(t.angles_deg(n - 1, 0) == 90.0);

  const BallbarSession session = commanded_session(plan);
  CHECK(session.samples.size() == 360 + 181 + 181 + 181 + 360 + 360 + 181);
  CHECK(session.tests() == std::vector<std::string>{"sphere_xy", "sphere_yz", "sphere_zx",
                                                    "radial_A", "axial_C", "radial_C", "axial_A"});
  CHECK(session.samples.back().length == 100.0);
  // The session writer accepts it and reads it back.
  const std::string text = format_ballbar(session);
  std::istringstream in(text);
  CHECK(parse_ballbar(in, "plan").samples.size() == session.samples.size());
}

TEST_CASE("tangential tests: the bar along the pivot's circle, at L0 throughout",
          "[ballbar][plan]") {
  for (MachineType m : {MachineType::AC_trt, MachineType::BC_trt}) {
    BallbarSetup s;
    s.machine = m;
    s.pivot = Eigen::Vector3d(110.0, -35.0, 70.0);
    s.tests = {BallbarTest::tangential_c, BallbarTest::tangential_tilt};
    const BallbarPlan plan = plan_ballbar_test(s);
    const std::string tilt(1, tilt_axis_letter(m));
    const PlanSegment& tc = segment_of(plan, "tangential_C");
    const PlanSegment& tt = segment_of(plan, "tangential_" + tilt);
    // Bar normal to the C axis and to the C radius through the pivot, written out by hand.
    const Eigen::Vector3d rc = Eigen::Vector3d(110.0, -35.0, 0.0).normalized();
    const Eigen::Vector3d bar_c = tc.samples.front().p_table - s.pivot;
    CHECK((bar_c - 100.0 * Eigen::Vector3d::UnitZ().cross(rc)).norm() < 1e-9);
    // Tilt axis X (A) or Y (B) through the origin: radius in the plane normal to it.
    const Eigen::Vector3d a =
        m == MachineType::AC_trt ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
    const Eigen::Vector3d rt = (s.pivot - a * a.dot(s.pivot)).normalized();
    CHECK(((tt.samples.front().p_table - s.pivot) - 100.0 * a.cross(rt)).norm() < 1e-9);
    for (const auto& seg : plan.segments)
      for (const auto& p : seg.samples) {
        const Eigen::Vector3d pivot_m = nominal_machine(m, p.tilt_deg, p.rot_deg, s.pivot);
        CHECK(std::abs((p.xyz - pivot_m).norm() - 100.0) < 1e-9);
      }
  }
  // A head axis turns the bar with it: refused by name.
  BallbarSetup h;
  h.machine = parse_machine_type("B-head-C-table");
  h.tilt_range_deg = default_tilt_range_deg(h.machine);
  h.tests = {BallbarTest::tangential_tilt};
  CHECK_THROWS_WITH(plan_ballbar_test(h),
                    Catch::Contains("tangential_B") && Catch::Contains("table axes"));
}

TEST_CASE("both directions and two feeds: runs, labels, reversals and times", "[ballbar][plan]") {
  BallbarSetup s;
  s.tests = {BallbarTest::radial_c, BallbarTest::tangential_tilt};
  s.directions = {SweepDirection::ccw, SweepDirection::cw};
  s.feed_factors = {1.0, 2.0};
  const BallbarPlan plan = plan_ballbar_test(s);
  std::vector<std::string> runs;
  for (const auto& seg : plan.segments)
    if (seg.kind == SegmentKind::test) runs.push_back(seg.label);
  CHECK(runs == std::vector<std::string>{"radial_C", "radial_C_cw", "radial_C_f2000",
                                         "radial_C_cw_f2000", "tangential_A", "tangential_A_cw",
                                         "tangential_A_f2000", "tangential_A_cw_f2000"});
  // The cw run sweeps the same poses back from where the ccw run ended, without its
  // repeated first pose; no transition between them.
  const PlanSegment& ccw = segment_of(plan, "radial_C");
  const PlanSegment& cw = segment_of(plan, "radial_C_cw");
  REQUIRE(ccw.samples.size() == 360);
  REQUIRE(cw.samples.size() == 359);
  CHECK(ccw.samples.back().rot_deg == 359.0);
  CHECK(cw.samples.front().rot_deg == 358.0);
  CHECK(cw.samples.back().rot_deg == 0.0);
  CHECK(cw.direction == SweepDirection::cw);
  CHECK(&plan.segments[1] == &cw);
  // At twice the feed a run takes half the time per step.
  const PlanSegment& fast = segment_of(plan, "radial_C_f2000");
  CHECK(fast.feed_factor == 2.0);
  const double slow_step = ccw.samples[11].time - ccw.samples[10].time;
  const double fast_step = fast.samples[11].time - fast.samples[10].time;
  CHECK(std::abs(fast_step - 0.5 * slow_step) < 1e-12);
  // Sphere tests run once.
  BallbarSetup sp = s;
  sp.tests = {BallbarTest::sphere_xy, BallbarTest::radial_c};
  std::size_t spheres = 0;
  for (const auto& seg : plan_ballbar_test(sp).segments)
    spheres += seg.label.rfind("sphere", 0) == 0;
  CHECK(spheres == 1);

  BallbarSetup bad = s;
  bad.feed_factors = {2.0, 1.0};
  CHECK_THROWS_WITH(plan_ballbar_test(bad), Catch::Contains("--feed-factors"));
  bad.feed_factors = {1.0, 1.0};
  CHECK_THROWS_WITH(plan_ballbar_test(bad), Catch::Contains("twice"));
  bad = s;
  bad.directions = {SweepDirection::cw, SweepDirection::cw};
  CHECK_THROWS_WITH(plan_ballbar_test(bad), Catch::Contains("--directions"));
  bad.directions = {};
  CHECK_THROWS_WITH(plan_ballbar_test(bad), Catch::Contains("--directions"));
  CHECK(parse_sweep_direction("cw") == SweepDirection::cw);
  CHECK_THROWS_WITH(parse_sweep_direction("clockwise"), Catch::Contains("clockwise"));
}

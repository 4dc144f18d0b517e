// SPDX-License-Identifier: BSD-3-Clause
// The single set-up ballbar test's program (plan.hpp): labels and names, and the plan in
// program order with machine axes and times; its segments are plan_segments.cpp.
#include "rotacal/ballbar/plan.hpp"

#include <algorithm>
#include <cmath>

#include "plan_segments.hpp"
#include "rotacal/core/error.hpp"

namespace rotacal {

using namespace plan_detail;

std::string test_label(BallbarTest test, MachineType machine) {
  const std::string tilt(1, tilt_axis_letter(machine));
  switch (test) {
    case BallbarTest::sphere_xy:
      return "sphere_xy";
    case BallbarTest::sphere_yz:
      return "sphere_yz";
    case BallbarTest::sphere_zx:
      return "sphere_zx";
    case BallbarTest::radial_tilt:
      return "radial_" + tilt;
    case BallbarTest::axial_tilt:
      return "axial_" + tilt;
    case BallbarTest::radial_c:
      return "radial_" + std::string(1, rot_axis_letter(machine));
    case BallbarTest::axial_c:
      return "axial_" + std::string(1, rot_axis_letter(machine));
    case BallbarTest::tangential_tilt:
      return "tangential_" + tilt;
    case BallbarTest::tangential_c:
      return "tangential_" + std::string(1, rot_axis_letter(machine));
  }
  ROTACAL_ASSERT(false);
  return {};
}

bool is_rotary_test(BallbarTest test) {
  return test != BallbarTest::sphere_xy && test != BallbarTest::sphere_yz &&
         test != BallbarTest::sphere_zx;
}

std::string run_label(BallbarTest test, SweepDirection direction, double feed_factor,
                      const BallbarSetup& setup) {
  std::string out = test_label(test, setup.machine);
  if (direction == SweepDirection::cw) out += "_cw";
  if (feed_factor != 1.0) {
    char b[40];
    std::snprintf(b, sizeof b, "_f%g", setup.feed_mm_per_min * feed_factor);
    out += b;
  }
  return out;
}

std::string test_of_run(const std::string& label) {
  std::string out = label;
  const std::size_t f = out.rfind("_f");
  if (f != std::string::npos && f + 2 < out.size() &&
      out.find_first_not_of("0123456789.e+-", f + 2) == std::string::npos)
    out.erase(f);
  if (out.size() > 3 && out.compare(out.size() - 3, 3, "_cw") == 0) out.erase(out.size() - 3);
  return out;
}

std::string to_string(SweepDirection d) { return d == SweepDirection::ccw ? "ccw" : "cw"; }

SweepDirection parse_sweep_direction(const std::string& text) {
  if (text == "ccw") return SweepDirection::ccw;
  if (text == "cw") return SweepDirection::cw;
  throw InvalidArgument("unknown sweep direction '" + text + "' (known: ccw, cw)");
}

BallbarTest parse_ballbar_test(const std::string& label, MachineType machine) {
  static const BallbarTest all[] = {
      BallbarTest::sphere_xy,   BallbarTest::sphere_yz,       BallbarTest::sphere_zx,
      BallbarTest::radial_tilt, BallbarTest::axial_tilt,      BallbarTest::radial_c,
      BallbarTest::axial_c,     BallbarTest::tangential_tilt, BallbarTest::tangential_c};
  std::string known;
  for (BallbarTest t : all) {
    if (test_label(t, machine) == label) return t;
    known += (known.empty() ? "" : ", ") + test_label(t, machine);
  }
  throw InvalidArgument("unknown ballbar test '" + label + "' for a " + to_string(machine) +
                        " machine (known: " + known + ")");
}

std::vector<BallbarTest> default_ballbar_tests() {
  return {BallbarTest::sphere_xy,   BallbarTest::sphere_yz, BallbarTest::sphere_zx,
          BallbarTest::radial_tilt, BallbarTest::axial_c,   BallbarTest::radial_c,
          BallbarTest::axial_tilt};
}

std::array<double, 2> default_tilt_range_deg(MachineType machine) {
  std::array<double, 2> r = {-90.0, 90.0};
  if (const auto& lim = machine.description().axis(machine.tilt_index()).limits_deg) {
    r[0] = std::max(r[0], (*lim)[0]);
    r[1] = std::min(r[1], (*lim)[1]);
  }
  return r;
}

double default_axial_c_tilt_deg(MachineType machine) {
  return machine.description().head_axes.size() == 2 ? 45.0 : 0.0;
}

std::string to_string(RadialSide side) {
  return side == RadialSide::outside ? "outside" : "inside";
}

RadialSide parse_radial_side(const std::string& text) {
  if (text == "outside" || text == "+") return RadialSide::outside;
  if (text == "inside" || text == "-") return RadialSide::inside;
  throw InvalidArgument("unknown radial side '" + text + "' (known: outside, inside, +, -)");
}

RotaryAngles<double> PlannedSample::angles_rad() const { return {tilt_deg * kDeg, rot_deg * kDeg}; }

std::size_t BallbarPlan::num_samples() const {
  std::size_t n = 0;
  for (const auto& s : segments) n += s.samples.size();
  return n;
}

double BallbarPlan::duration() const {
  for (auto it = segments.rbegin(); it != segments.rend(); ++it)
    if (!it->samples.empty()) return it->samples.back().time;
  return 0.0;
}

BallbarPlan plan_ballbar_test(const BallbarSetup& setup,
                              const std::optional<LocationErrors<double>>& identified) {
  validate(setup);
  if (identified) require(identified->v.allFinite(), "identified location errors must be finite");

  BallbarPlan plan;
  plan.setup = setup;
  plan.compensation = identified;

  for (BallbarTest t : setup.tests) {
    const std::vector<double> feeds =
        is_rotary_test(t) ? setup.feed_factors : std::vector<double>{1.0};
    const std::vector<SweepDirection> dirs =
        is_rotary_test(t) ? setup.directions : std::vector<SweepDirection>{SweepDirection::ccw};
    for (double f : feeds) {
      for (SweepDirection dir : dirs) {
        PlanSegment test = make_test(setup, t, dir, f);
        if (!plan.segments.empty()) {
          // A run that starts where the previous one ended (a cw run after its ccw one, the
          // axis reversing there) begins one step on: that pose was read by the previous run.
          const PlannedSample& end = plan.segments.back().samples.back();
          const PlannedSample& start = test.samples.front();
          if ((end.p_table - start.p_table).norm() < kLengthTol && end.tilt_deg == start.tilt_deg &&
              end.rot_deg == start.rot_deg && test.samples.size() > 1)
            test.samples.erase(test.samples.begin());
        }
        ROTACAL_ASSERT(!test.samples.empty());
        if (!plan.segments.empty()) {
          const PlannedSample& last = plan.segments.back().samples.back();
          // segments.back() is the previous test here, never a transition.
          for (PlanSegment& tr : transitions(setup, last, test.samples.front())) {
            // A rotary move of one step has no point of its own: the next test's first sample
            // is its end. An arc without points still is a move (it carries its geometry).
            if (tr.kind == SegmentKind::rotary_transition && tr.samples.empty()) continue;
            plan.segments.push_back(std::move(tr));
          }
        }
        plan.segments.push_back(std::move(test));
      }
    }
  }

  // Machine axes (inverse kinematics on the nominal or identified model) and time stamps.
  const LocationErrors<double> e = identified ? *identified : LocationErrors<double>();
  const PlannedSample* prev = nullptr;
  for (PlanSegment& seg : plan.segments) {
    for (PlannedSample& s : seg.samples) {
      s.xyz = inverse(setup.machine, e, s.angles_rad(), s.p_table).xyz;
      if (prev == nullptr) {
        s.time = 0.0;
      } else {
        // The move to a sample runs at the feeds of the segment the sample belongs to.
        const double linear =
            (s.xyz - prev->xyz).norm() / (setup.feed_mm_per_min * seg.feed_factor);
        const double rotary =
            std::max(std::abs(s.tilt_deg - prev->tilt_deg), std::abs(s.rot_deg - prev->rot_deg)) /
            (setup.feed_deg_per_min * seg.feed_factor);
        const double dt = 60.0 * std::max(linear, rotary);
        ROTACAL_ASSERT(dt > 0.0);
        s.time = prev->time + dt;
      }
      prev = &s;
    }
  }
  require(plan.duration() <= kMaxProgramSeconds,
          "the program would run " + format_number_or_nan(plan.duration() / 3600.0) +
              " h (more than 24 h): check --length, --step and the feeds");
  return plan;
}

PlanTable tabulate(const BallbarPlan& plan) {
  PlanTable t;
  const auto n = static_cast<Eigen::Index>(plan.num_samples());
  t.labels.reserve(static_cast<std::size_t>(n));
  t.segment.reserve(static_cast<std::size_t>(n));
  t.time.resize(n);
  t.p_table.resize(n, 3);
  t.angles_deg.resize(n, 2);
  t.machine_axes.resize(n, 5);
  Eigen::Index i = 0;
  for (std::size_t k = 0; k < plan.segments.size(); ++k) {
    for (const PlannedSample& s : plan.segments[k].samples) {
      t.labels.push_back(plan.segments[k].label);
      t.segment.push_back(static_cast<int>(k));
      t.time[i] = s.time;
      t.p_table.row(i) = s.p_table.transpose();
      t.angles_deg.row(i) << s.tilt_deg, s.rot_deg;
      t.machine_axes.row(i) << s.xyz.x(), s.xyz.y(), s.xyz.z(), s.tilt_deg, s.rot_deg;
      ++i;
    }
  }
  return t;
}

BallbarSession commanded_session(const BallbarPlan& plan) {
  BallbarSession session;
  session.machine = plan.setup.machine;
  session.ballbar_length = plan.setup.ballbar_length;
  session.pivot = plan.setup.pivot;
  for (const PlanSegment& seg : plan.segments) {
    if (seg.kind != SegmentKind::test) continue;
    for (const PlannedSample& s : seg.samples) {
      BallbarSample b;
      b.test = seg.label;
      b.time = s.time;
      b.xyz = s.xyz;
      b.tilt_deg = s.tilt_deg;
      b.rot_deg = s.rot_deg;
      b.length = plan.setup.ballbar_length;
      session.samples.push_back(std::move(b));
    }
  }
  return session;
}

}  // namespace rotacal

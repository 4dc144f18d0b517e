// SPDX-License-Identifier: BSD-3-Clause
// The segments of the single set-up ballbar test (plan_segments.hpp).
#include "plan_segments.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "rotacal/core/error.hpp"

namespace rotacal::plan_detail {

// Grid tolerance for angles, deg (far below any NC resolution, far above the rounding of
// lo + k * step).
constexpr double kAngleTol = 1e-9;
// Largest number of samples one sweep may have (a guard against step = 1e-12 exhausting memory).
constexpr double kMaxSamplesPerSweep = 1e6;

void require(bool ok, const std::string& what) {
  if (!ok) throw InvalidArgument("plan_ballbar_test: " + what);
}

std::string format_number_or_nan(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

bool finite3(const Eigen::Vector3d& v) { return v.allFinite(); }

// lo + k step for k = 0, 1, ... up to hi; hi is appended when it is off the grid. A span of
// exactly 360 deg is a full turn: the end pose repeats the start and is left out.
std::vector<double> sweep(double lo, double hi, double step) {
  const double span = hi - lo;
  const bool full_turn = std::abs(span - 360.0) < kAngleTol;
  const double n_real = span / step;
  const long n = static_cast<long>(std::floor(n_real + kAngleTol));
  std::vector<double> v;
  v.reserve(static_cast<std::size_t>(n) + 2);
  for (long k = 0; k <= n; ++k) v.push_back(lo + static_cast<double>(k) * step);
  const bool on_grid = std::abs(n_real - static_cast<double>(n)) < kAngleTol;
  if (full_turn) {
    if (on_grid) v.pop_back();
  } else if (!on_grid) {
    v.push_back(hi);
  }
  return v;
}

void check_range(const std::array<double, 2>& r, const char* name, double step) {
  const std::string n = name;
  require(std::isfinite(r[0]) && std::isfinite(r[1]), n + " must be finite");
  require(r[1] > r[0], n + " must be increasing (got " + std::to_string(r[0]) + ", " +
                           std::to_string(r[1]) + ")");
  require(r[1] - r[0] <= 360.0 + kAngleTol,
          n + " spans " + std::to_string(r[1] - r[0]) + " deg, more than a full turn");
  require((r[1] - r[0]) / step <= kMaxSamplesPerSweep,
          n + " / step_deg (--step) gives more than 1e6 samples per sweep");
}

// Limits of a set-up that a machine tool can run; each message names the field and the
// command-line option that sets it.
constexpr double kMaxBallbarLength = 2000.0;  // mm: the longest ballbars are ~600 mm
constexpr double kMaxPivot = 1.0e4;           // mm from the table origin
constexpr double kMaxFeed = 1.0e6;            // mm/min and deg/min

void validate(const BallbarSetup& s) {
  require(std::isfinite(s.ballbar_length) && s.ballbar_length >= 1.0 &&
              s.ballbar_length <= kMaxBallbarLength,
          "ballbar_length (--length) must be within [1, 2000] mm, got " +
              format_number_or_nan(s.ballbar_length));
  require(finite3(s.pivot) && s.pivot.cwiseAbs().maxCoeff() <= kMaxPivot,
          "pivot (--pivot) must be finite and within 10000 mm of the table origin");
  require(std::isfinite(s.step_deg) && s.step_deg > 0.0 && s.step_deg <= 90.0,
          "step_deg (--step) must be in (0, 90] deg");
  require(
      std::isfinite(s.feed_mm_per_min) && s.feed_mm_per_min > 0.0 && s.feed_mm_per_min <= kMaxFeed,
      "feed_mm_per_min (--feed) must be in (0, 1e6] mm/min");
  require(std::isfinite(s.feed_deg_per_min) && s.feed_deg_per_min > 0.0 &&
              s.feed_deg_per_min <= kMaxFeed,
          "feed_deg_per_min (--rotary-feed) must be in (0, 1e6] deg/min");
  check_range(s.tilt_range_deg, "tilt_range_deg (--a-range/--b-range)", s.step_deg);
  require(s.tilt_range_deg[0] >= -180.0 && s.tilt_range_deg[1] <= 180.0,
          "tilt_range_deg (--a-range/--b-range) must lie within [-180, 180] deg");
  check_range(s.rot_range_deg, "rot_range_deg (--c-range)", s.step_deg);
  if (s.axial_c_tilt_deg)
    require(std::isfinite(*s.axial_c_tilt_deg) && std::abs(*s.axial_c_tilt_deg) <= 180.0,
            "axial_c_tilt_deg must lie within [-180, 180] deg");
  // The machine's rotary limits (formats.md limits_deg) bound every angle the plan commands.
  const MachineDescription& d = s.machine.description();
  auto within = [&](int k, double lo, double hi, const std::string& what) {
    const auto& lim = d.axis(k).limits_deg;
    if (lim)
      require(lo >= (*lim)[0] - kAngleTol && hi <= (*lim)[1] + kAngleTol,
              what + " reaches " + std::string(1, d.axis(k).name) + " beyond its limits [" +
                  format_number_or_nan((*lim)[0]) + ", " + format_number_or_nan((*lim)[1]) +
                  "] deg");
  };
  within(s.machine.tilt_index(), std::min(0.0, s.tilt_range_deg[0]),
         std::max(0.0, s.tilt_range_deg[1]),
         "tilt_range_deg (--a-range/--b-range) with the tests at tilt 0");
  within(s.machine.rot_index(), std::min(0.0, s.rot_range_deg[0]),
         std::max(0.0, s.rot_range_deg[1]), "rot_range_deg (--c-range) with the tests at 0");
  require(!s.tests.empty(), "tests is empty");
  for (std::size_t i = 0; i < s.tests.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      require(s.tests[i] != s.tests[j],
              "test " + test_label(s.tests[i], s.machine) + " is listed twice");
  for (BallbarTest t : s.tests)
    if (t == BallbarTest::tangential_tilt || t == BallbarTest::tangential_c)
      require(!d.axis(t == BallbarTest::tangential_tilt ? s.machine.tilt_index()
                                                        : s.machine.rot_index())
                   .on_head,
              "test " + test_label(t, s.machine) +
                  " is planned for table axes only: a head axis turns the bar's direction with it");
  require(!s.directions.empty(), "directions (--directions) is empty");
  for (std::size_t i = 0; i < s.directions.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      require(s.directions[i] != s.directions[j],
              "direction " + to_string(s.directions[i]) + " is listed twice (--directions)");
  require(!s.feed_factors.empty() && s.feed_factors[0] == 1.0,
          "feed_factors (--feed-factors) must start with 1: the first run of a test is at the "
          "set-up's feeds");
  for (std::size_t i = 0; i < s.feed_factors.size(); ++i) {
    const double k = s.feed_factors[i];
    require(std::isfinite(k) && k > 0.0 && k <= 100.0 && k * s.feed_mm_per_min <= kMaxFeed &&
                k * s.feed_deg_per_min <= kMaxFeed,
            "feed factor " + format_number_or_nan(k) +
                " (--feed-factors) must be in (0, 100] with the feeds within 1e6 per min");
    for (std::size_t j = 0; j < i; ++j)
      require(run_label(BallbarTest::radial_c, SweepDirection::ccw, s.feed_factors[j], s) !=
                  run_label(BallbarTest::radial_c, SweepDirection::ccw, k, s),
              "feed factor " + format_number_or_nan(k) +
                  " is listed twice or gives the same run label as another (--feed-factors)");
  }
}

// Unit vector from the nominal line of a table axis to the pivot, in the plane normal to the
// axis. Throws if the pivot lies on the axis (no radial direction).
Eigen::Vector3d radial_direction(const Eigen::Vector3d& pivot, const RotaryAxis& axis,
                                 const std::string& test) {
  const Eigen::Vector3d d = pivot - axis.point;
  const Eigen::Vector3d r = d - axis.direction * axis.direction.dot(d);
  require(r.norm() > 1e-6, test + " needs the pivot off the axis it turns about (pivot is " +
                               std::to_string(r.norm()) + " mm from it)");
  return r.normalized();
}

// A head axis moves the tool, not the pivot: the ball stays put on the table while the head
// turns (TCPM), so any bar direction normal to the axis is radial. The horizontal one
// normal to the axis (X for a vertical axis) keeps the tool cup's angles small.
Eigen::Vector3d head_radial_direction(const RotaryAxis& axis) {
  const Eigen::Vector3d h = axis.direction.cross(Eigen::Vector3d::UnitZ());
  return h.norm() > 1e-9 ? Eigen::Vector3d(h.normalized()) : Eigen::Vector3d::UnitX();
}

// The table-frame tool point of a test that keeps the tool fixed on the table: the bar normal
// to the axis under test (radial) or along it (axial), as Flynn et al. Secs. 3.2-3.3 lay it
// out for the table axes.
Eigen::Vector3d fixed_tool_point(const BallbarSetup& s, BallbarTest t) {
  const Eigen::Vector3d& p = s.pivot;
  const double L = s.ballbar_length;
  const std::string label = test_label(t, s.machine);
  const MachineDescription& d = s.machine.description();
  const bool tilt_test = t == BallbarTest::radial_tilt || t == BallbarTest::axial_tilt ||
                         t == BallbarTest::tangential_tilt;
  const RotaryAxis& axis = d.axis(tilt_test ? s.machine.tilt_index() : s.machine.rot_index());
  const double sign = !tilt_test && s.radial_c_side == RadialSide::inside ? -1.0 : 1.0;
  switch (t) {
    case BallbarTest::radial_tilt:
    case BallbarTest::radial_c:
      return p +
             sign * L *
                 (axis.on_head ? head_radial_direction(axis) : radial_direction(p, axis, label));
    case BallbarTest::axial_tilt:
    case BallbarTest::axial_c:
      return p + L * axis.direction;
    case BallbarTest::tangential_tilt:  // along the circle the pivot follows (validate: table axes)
    case BallbarTest::tangential_c:
      return p + L * axis.direction.cross(radial_direction(p, axis, label)).normalized();
    default:
      break;
  }
  ROTACAL_ASSERT(false);
  return p;
}

PlannedSample make_sample(const Eigen::Vector3d& p_table, double tilt_deg, double rot_deg) {
  PlannedSample s;
  s.p_table = p_table;
  s.tilt_deg = tilt_deg;
  s.rot_deg = rot_deg;
  return s;
}

PlanSegment make_test(const BallbarSetup& s, BallbarTest t, SweepDirection direction,
                      double feed_factor) {
  PlanSegment seg;
  seg.label = run_label(t, direction, feed_factor, s);
  seg.kind = SegmentKind::test;
  seg.test = t;
  seg.direction = direction;
  seg.feed_factor = feed_factor;
  const Eigen::Vector3d& p = s.pivot;
  const double L = s.ballbar_length;
  switch (t) {
    case BallbarTest::sphere_xy:
      for (double a : sweep(0.0, 360.0, s.step_deg))
        seg.samples.push_back(make_sample(
            p + L * Eigen::Vector3d(std::cos(a * kDeg), std::sin(a * kDeg), 0.0), 0, 0));
      break;
    case BallbarTest::sphere_yz:
      for (double a : sweep(0.0, 180.0, s.step_deg))
        seg.samples.push_back(make_sample(
            p + L * Eigen::Vector3d(0.0, std::cos(a * kDeg), std::sin(a * kDeg)), 0, 0));
      break;
    case BallbarTest::sphere_zx:
      for (double a : sweep(0.0, 180.0, s.step_deg))
        seg.samples.push_back(make_sample(
            p + L * Eigen::Vector3d(std::cos(a * kDeg), 0.0, std::sin(a * kDeg)), 0, 0));
      break;
    case BallbarTest::radial_tilt:
    case BallbarTest::axial_tilt:
    case BallbarTest::tangential_tilt: {
      const Eigen::Vector3d q = fixed_tool_point(s, t);
      for (double a : sweep(s.tilt_range_deg[0], s.tilt_range_deg[1], s.step_deg))
        seg.samples.push_back(make_sample(q, a, 0.0));
      break;
    }
    case BallbarTest::radial_c:
    case BallbarTest::axial_c:
    case BallbarTest::tangential_c: {
      const Eigen::Vector3d q = fixed_tool_point(s, t);
      const double tilt = t == BallbarTest::axial_c
                              ? s.axial_c_tilt_deg.value_or(default_axial_c_tilt_deg(s.machine))
                              : 0.0;
      for (double a : sweep(s.rot_range_deg[0], s.rot_range_deg[1], s.step_deg))
        seg.samples.push_back(make_sample(q, tilt, a));
      break;
    }
  }
  // A cw run is the same poses swept back, from the end of the ccw one.
  if (direction == SweepDirection::cw) std::reverse(seg.samples.begin(), seg.samples.end());
  return seg;
}

PlanSegment transition(SegmentKind kind) {
  PlanSegment seg;
  seg.label = "transition";
  seg.kind = kind;
  return seg;
}

int intervals(double extent_deg, double step_deg) {
  return std::max(1, static_cast<int>(std::ceil(extent_deg / step_deg - kAngleTol)));
}

// Rotary axes from (t0, c0) to (t1, c1) with the tool fixed on the table at q (any path of
// the axes keeps the ballbar in place). Both axes turn together by step_deg per block until
// each reaches its end, so from on-grid angles every commanded angle stays on the grid (no
// A-17.0474 in the program). Holds the points after the start, the end only if `include_end`.
PlanSegment rotary_move(const Eigen::Vector3d& q, double t0, double c0, double t1, double c1,
                        double step_deg, bool include_end) {
  PlanSegment seg = transition(SegmentKind::rotary_transition);
  const int n = intervals(std::max(std::abs(t1 - t0), std::abs(c1 - c0)), step_deg);
  auto towards = [step_deg](double from, double to, int k) {
    const double d = std::min(static_cast<double>(k) * step_deg, std::abs(to - from));
    return to >= from ? from + d : from - d;
  };
  for (int k = 1; k < n; ++k)
    seg.samples.push_back(make_sample(q, towards(t0, t1, k), towards(c0, c1, k)));
  if (include_end) seg.samples.push_back(make_sample(q, t1, c1));
  return seg;
}

// Great-circle arc about the pivot from a to b (both at distance L0 from it) at rotary zero.
PlanSegment arc_move(const Eigen::Vector3d& pivot, const Eigen::Vector3d& a,
                     const Eigen::Vector3d& b, double step_deg, bool include_end) {
  PlanSegment seg = transition(SegmentKind::arc_transition);
  const Eigen::Vector3d u = (a - pivot).normalized();
  const Eigen::Vector3d w = (b - pivot).normalized();
  const double L = (a - pivot).norm();
  const Eigen::Vector3d cross = u.cross(w);
  const double s = cross.norm();
  const double c = u.dot(w);
  Eigen::Vector3d axis;
  if (s > 1e-12) {
    axis = cross / s;
  } else {
    // Opposite ends (same ends never get here): any great circle through both works; take the
    // one over the top of the pivot (rotating u about u x Z moves it towards +Z), or the ZX
    // plane when u is vertical.
    const Eigen::Vector3d uz = u.cross(Eigen::Vector3d::UnitZ());
    axis = uz.norm() > 1e-12 ? Eigen::Vector3d(uz.normalized()) : Eigen::Vector3d::UnitY();
  }
  const double angle = std::atan2(s, c);
  seg.arc.start = a;
  seg.arc.end = b;
  seg.arc.center = pivot;
  seg.arc.axis = axis;
  seg.arc.angle = angle;
  seg.arc.principal_axis = -1;
  for (int i = 0; i < 3; ++i) {
    Eigen::Vector3d e = Eigen::Vector3d::Zero();
    e[i] = 1.0;
    if ((axis - e).norm() < 1e-12 || (axis + e).norm() < 1e-12) {
      seg.arc.principal_axis = i;
      seg.arc.axis = axis[i] > 0 ? e : Eigen::Vector3d(-e);  // exact, so the plane stays exact
    }
  }
  const int n = intervals(angle / kDeg, step_deg);
  for (int k = 1; k < n; ++k) {
    const double phi = angle * static_cast<double>(k) / n;
    seg.samples.push_back(
        make_sample(pivot + L * (rotation_about_axis<double>(seg.arc.axis, phi) * u), 0.0, 0.0));
  }
  if (include_end) seg.samples.push_back(make_sample(b, 0.0, 0.0));
  return seg;
}

bool at_zero(const PlannedSample& s) { return s.tilt_deg == 0.0 && s.rot_deg == 0.0; }

// The moves from the last sample of one test to the first sample of the next, in order; every
// one keeps the tool at L0 from the pivot. The last move stops short of `to`, which is the
// next test's first sample.
std::vector<PlanSegment> transitions(const BallbarSetup& s, const PlannedSample& from,
                                     const PlannedSample& to) {
  struct Move {
    enum { rotary, arc } kind;
    Eigen::Vector3d a, b;
    double t0, c0, t1, c1;
  };
  std::vector<Move> moves;
  const bool same_point = (from.p_table - to.p_table).norm() < kLengthTol;
  const bool same_angles = from.tilt_deg == to.tilt_deg && from.rot_deg == to.rot_deg;
  if (same_point) {
    if (!same_angles)
      moves.push_back({Move::rotary, from.p_table, from.p_table, from.tilt_deg, from.rot_deg,
                       to.tilt_deg, to.rot_deg});
  } else {
    if (!at_zero(from))
      moves.push_back(
          {Move::rotary, from.p_table, from.p_table, from.tilt_deg, from.rot_deg, 0.0, 0.0});
    moves.push_back({Move::arc, from.p_table, to.p_table, 0.0, 0.0, 0.0, 0.0});
    if (!at_zero(to))
      moves.push_back({Move::rotary, to.p_table, to.p_table, 0.0, 0.0, to.tilt_deg, to.rot_deg});
  }
  std::vector<PlanSegment> out;
  for (std::size_t i = 0; i < moves.size(); ++i) {
    const Move& m = moves[i];
    const bool include_end = i + 1 < moves.size();
    if (m.kind == Move::rotary)
      out.push_back(rotary_move(m.a, m.t0, m.c0, m.t1, m.c1, s.step_deg, include_end));
    else
      out.push_back(arc_move(s.pivot, m.a, m.b, s.step_deg, include_end));
  }
  return out;
}

}  // namespace rotacal::plan_detail

// SPDX-License-Identifier: BSD-3-Clause
#include "rotacal/circular/plan.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <set>

#include "../io/nc_words.hpp"
#include "rotacal/core/angles.hpp"
#include "rotacal/core/error.hpp"

namespace rotacal {

namespace {

constexpr std::size_t kMinReadingsPerArc = 36;
constexpr std::size_t kMaxReadings = 2000000;

using nc_detail::fixed;
using nc_detail::general;

void require_plan(bool ok, const std::string& what) {
  if (!ok) throw InvalidArgument("plan_circular_test: " + what);
}

// Ball centre minus commanded X, Y, Z at rotary zero: the tool vector on a head machine.
Eigen::Vector3d zero_tool_vector(MachineType m) { return tool_vector<double>(m, 0.0); }

}  // namespace

std::string to_string(CircularPlane plane) {
  switch (plane) {
    case CircularPlane::XY:
      return "XY";
    case CircularPlane::YZ:
      return "YZ";
    case CircularPlane::ZX:
      return "ZX";
  }
  ROTACAL_ASSERT(false);
  return {};
}

CircularPlane parse_circular_plane(const std::string& text) {
  std::string up = text;
  for (char& c : up) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  for (CircularPlane p : {CircularPlane::XY, CircularPlane::YZ, CircularPlane::ZX})
    if (to_string(p) == up) return p;
  throw InvalidArgument("plane: unknown circular-test plane '" + text + "' (known: XY, YZ, ZX)");
}

std::array<int, 2> plane_axes(CircularPlane plane) {
  const int n = plane_normal(plane);
  return {(n + 1) % 3, (n + 2) % 3};  // XY: (0, 1); YZ: (1, 2); ZX: (2, 0)
}

int plane_normal(CircularPlane plane) {
  switch (plane) {
    case CircularPlane::XY:
      return 2;
    case CircularPlane::YZ:
      return 0;
    case CircularPlane::ZX:
      return 1;
  }
  ROTACAL_ASSERT(false);
  return 2;
}

std::string to_string(CircularDirection direction) {
  return direction == CircularDirection::ccw ? "ccw" : "cw";
}

CircularDirection parse_circular_direction(const std::string& text) {
  if (text == "ccw" || text == "CCW") return CircularDirection::ccw;
  if (text == "cw" || text == "CW") return CircularDirection::cw;
  throw InvalidArgument("direction: unknown circular-test direction '" + text +
                        "' (known: ccw, cw)");
}

double CircularRun::omega_rad_s() const { return rate_deg_s * kDeg; }

double CircularRun::angle_at(double t) const {
  return run_in_from_deg + rate_deg_s * (t - t_start);
}

std::size_t CircularPlanResult::num_samples() const {
  std::size_t n = 0;
  for (const CircularRun& r : runs) n += r.time.size();
  return n;
}

std::string circular_label(CircularPlane plane, CircularDirection direction, double feed_mm_per_min,
                           bool with_feed) {
  std::string s = "circular_" + to_string(plane) + "_" + to_string(direction);
  if (with_feed) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", feed_mm_per_min);
    s += std::string("_f") + buf;
  }
  return s;
}

Eigen::Vector3d circular_point(const CircularTestPlan& plan, CircularPlane plane,
                               double theta_deg) {
  const auto ax = plane_axes(plane);
  Eigen::Vector3d p = plan.centre;
  p[ax[0]] += plan.radius * std::cos(theta_deg * kDeg);
  p[ax[1]] += plan.radius * std::sin(theta_deg * kDeg);
  return p;
}

CircularPlanResult plan_circular_test(const CircularTestPlan& plan) {
  require_plan(std::isfinite(plan.radius) && plan.radius > 0.0 && plan.radius <= 1e4,
               "radius must be in (0, 10000] mm, got " + general(plan.radius));
  require_plan(plan.centre.allFinite() && plan.centre.cwiseAbs().maxCoeff() <= 1e5,
               "centre must be finite and within +-1e5 mm");
  require_plan(!plan.planes.empty(), "planes: at least one plane (XY, YZ, ZX) is needed");
  require_plan(!plan.feeds_mm_per_min.empty(), "feeds_mm_per_min: at least one feed is needed");
  require_plan(!plan.directions.empty(), "directions: at least one direction (ccw, cw) is needed");
  require_plan(
      std::set<CircularPlane>(plan.planes.begin(), plan.planes.end()).size() == plan.planes.size(),
      "planes: a plane is repeated");
  require_plan(std::set<CircularDirection>(plan.directions.begin(), plan.directions.end()).size() ==
                   plan.directions.size(),
               "directions: a direction is repeated");
  for (double f : plan.feeds_mm_per_min)
    require_plan(std::isfinite(f) && f > 0.0 && f <= 1e5,
                 "feeds_mm_per_min: each feed must be in (0, 100000] mm/min, got " + general(f));
  require_plan(
      std::set<double>(plan.feeds_mm_per_min.begin(), plan.feeds_mm_per_min.end()).size() ==
          plan.feeds_mm_per_min.size(),
      "feeds_mm_per_min: a feed is repeated");
  require_plan(std::isfinite(plan.span_deg) && plan.span_deg > 0.0 && plan.span_deg <= 360.0,
               "span_deg must be in (0, 360], got " + general(plan.span_deg));
  require_plan(std::isfinite(plan.start_deg) && std::abs(plan.start_deg) <= 3600.0,
               "start_deg must be finite and within +-3600, got " + general(plan.start_deg));
  require_plan(std::isfinite(plan.run_in_deg) && plan.run_in_deg >= 0.0 && plan.run_in_deg <= 360.0,
               "run_in_deg must be in [0, 360], got " + general(plan.run_in_deg));
  require_plan(
      std::isfinite(plan.overshoot_deg) && plan.overshoot_deg >= 0.0 && plan.overshoot_deg <= 360.0,
      "overshoot_deg must be in [0, 360], got " + general(plan.overshoot_deg));
  require_plan(
      std::isfinite(plan.sample_rate_hz) && plan.sample_rate_hz > 0.0 && plan.sample_rate_hz <= 1e5,
      "sample_rate_hz must be in (0, 100000], got " + general(plan.sample_rate_hz));
  require_plan(std::isfinite(plan.remount_s) && plan.remount_s >= 0.0 && plan.remount_s <= 86400.0,
               "remount_s must be in [0, 86400], got " + general(plan.remount_s));

  CircularPlanResult out;
  out.plan = plan;
  const bool with_feed = plan.feeds_mm_per_min.size() > 1;
  double t = 0.0;
  std::size_t total = 0;
  for (std::size_t ip = 0; ip < plan.planes.size(); ++ip) {
    if (ip > 0) t += plan.remount_s;
    double angle_now = 0.0;
    bool first_in_plane = true;
    for (double feed : plan.feeds_mm_per_min) {
      const double speed = feed / 60.0;                    // mm/s
      const double rate_deg = speed / plan.radius / kDeg;  // deg/s
      for (CircularDirection d : plan.directions) {
        CircularRun r;
        r.plane = plan.planes[ip];
        r.direction = d;
        r.feed_mm_per_min = feed;
        r.label = circular_label(r.plane, d, feed, with_feed);
        const double s = d == CircularDirection::ccw ? 1.0 : -1.0;
        const double a0 = plan.start_deg, a1 = plan.start_deg + plan.span_deg;
        r.data_from_deg = d == CircularDirection::ccw ? a0 : a1;
        r.data_to_deg = d == CircularDirection::ccw ? a1 : a0;
        r.run_in_from_deg = r.data_from_deg - s * plan.run_in_deg;
        r.overshoot_to_deg = r.data_to_deg + s * plan.overshoot_deg;
        // Move along the circle (bar mounted) to the run-in start, the short way, at this feed.
        if (!first_in_plane) {
          double move = std::remainder(r.run_in_from_deg - angle_now, 360.0);
          t += std::abs(move) / rate_deg + 1.0;  // the arc and a 1 s dwell
        }
        first_in_plane = false;
        r.t_start = t;
        r.rate_deg_s = s * rate_deg;
        const double t_data = t + plan.run_in_deg / rate_deg;
        const double duration = plan.span_deg / rate_deg;
        const std::size_t n =
            static_cast<std::size_t>(std::floor(duration * plan.sample_rate_hz + 1e-9)) + 1;
        if (n < kMinReadingsPerArc)
          throw InvalidArgument("plan_circular_test: feeds_mm_per_min: " + general(feed) +
                                " mm/min gives only " + std::to_string(n) +
                                " readings over the data arc at sample_rate_hz " +
                                general(plan.sample_rate_hz) + " (at least 36 are needed)");
        total += n;
        if (total > kMaxReadings)
          throw InvalidArgument(
              "plan_circular_test: the plan has more than 2,000,000 readings "
              "(lower sample_rate_hz, raise feeds_mm_per_min or plan fewer runs)");
        r.time.resize(n);
        r.angle_deg.resize(n);
        for (std::size_t k = 0; k < n; ++k) {
          const double dt = static_cast<double>(k) / plan.sample_rate_hz;
          r.time[k] = t_data + dt;
          r.angle_deg[k] = r.data_from_deg + s * rate_deg * dt;
        }
        t = t_data + duration + plan.overshoot_deg / rate_deg;
        angle_now = r.overshoot_to_deg;
        out.runs.push_back(std::move(r));
      }
    }
  }
  return out;
}

BallbarSession circular_commanded_session(const CircularPlanResult& result) {
  const CircularTestPlan& plan = result.plan;
  BallbarSession session;
  session.machine = plan.machine;
  session.ballbar_length = plan.radius;
  session.pivot = plan.centre;
  const Eigen::Vector3d tv = zero_tool_vector(plan.machine);
  session.samples.reserve(result.num_samples());
  for (const CircularRun& r : result.runs)
    for (std::size_t k = 0; k < r.time.size(); ++k) {
      BallbarSample b;
      b.test = r.label;
      b.time = r.time[k];
      b.xyz = circular_point(plan, r.plane, r.angle_deg[k]) - tv;
      b.length = plan.radius;
      session.samples.push_back(std::move(b));
    }
  return session;
}

namespace {

class CircularNcWriter {
 public:
  CircularNcWriter(const CircularPlanResult& r, NcDialect d, const NcProgramOptions& o)
      : res_(r),
        plan_(r.plan),
        d_(d),
        o_(o),
        tv_(zero_tool_vector(r.plan.machine)),
        tilt_(1, tilt_axis_letter(r.plan.machine)),
        rot_(1, rot_axis_letter(r.plan.machine)) {}

  std::string run() {
    prologue();
    for (std::size_t i = 0; i < res_.runs.size(); ++i) {
      const CircularRun& r = res_.runs[i];
      const bool new_plane = i == 0 || res_.runs[i - 1].plane != r.plane;
      if (new_plane) {
        if (i > 0 && o_.stop_to_mount) {
          comment("remove the ballbar: next plane " + to_string(r.plane));
          line(d_ == NcDialect::heidenhain ? "STOP" : "M0");
        }
        approach(r);
      }
      comment("RUN " + r.label + ": " + to_string(r.direction) + " at " +
              general(r.feed_mm_per_min) + " mm/min; run-in from " + general(r.run_in_from_deg) +
              " deg, data arc " + general(r.data_from_deg) + " .. " + general(r.data_to_deg) +
              " deg, overshoot to " + general(r.overshoot_to_deg) + " deg");
      if (!new_plane) {  // along the circle, the short way, to the run-in start
        const double move = std::remainder(r.run_in_from_deg - angle_, 360.0);
        if (std::abs(move) > 1e-9) arcs(r.plane, angle_, angle_ + move, r.feed_mm_per_min);
        angle_ = r.run_in_from_deg;
      }
      arcs(r.plane, r.run_in_from_deg, r.overshoot_to_deg, r.feed_mm_per_min);
      angle_ = r.overshoot_to_deg;
    }
    comment("end of test: remove the ballbar");
    epilogue();
    std::string out;
    for (std::size_t i = 0; i < lines_.size(); ++i) {
      if (d_ == NcDialect::heidenhain) out += std::to_string(i) + " ";
      out += lines_[i] + "\n";
    }
    return out;
  }

 private:
  void line(const std::string& s) { lines_.push_back(s); }

  // Every comment, fixed or free text (a machine's name), through the dialect's writer.
  void comment(const std::string& text) {
    for (const std::string& l : comment_lines(nc_detail::comment_dialect(d_), text)) line(l);
  }

  std::string num(double v) const {
    std::string s = fixed(v, o_.decimals);
    if (d_ == NcDialect::heidenhain && s[0] != '-') s = "+" + s;
    return s;
  }

  // Programmed coordinates of the ball at path angle theta: machine axes on linuxcnc (the ball
  // less the tool vector on a head machine, as the rotary test's program), else the ball
  // itself under the controller's tool length compensation.
  Eigen::Vector3d coords(CircularPlane plane, double theta_deg) const {
    const Eigen::Vector3d ball = circular_point(plan_, plane, theta_deg);
    return d_ == NcDialect::linuxcnc ? Eigen::Vector3d(ball - tv_) : ball;
  }
  Eigen::Vector3d centre() const {
    return d_ == NcDialect::linuxcnc ? Eigen::Vector3d(plan_.centre - tv_) : plan_.centre;
  }

  // Circular blocks from path angle a to b (deg), at most 90 deg each.
  void arcs(CircularPlane plane, double a, double b, double feed) {
    const int n = plane_normal(plane);
    const int lo = std::min((n + 1) % 3, (n + 2) % 3), hi = std::max((n + 1) % 3, (n + 2) % 3);
    const char* names = "XYZ";
    const char* centre_names = "IJK";
    static const char* planes[] = {"G19", "G18", "G17"};
    const bool positive = b > a;
    const int pieces = std::max(1, static_cast<int>(std::ceil(std::abs(b - a) / 90.0 - 1e-9)));
    const Eigen::Vector3d c = centre();
    for (int k = 1; k <= pieces; ++k) {
      const double from = a + (b - a) * (k - 1) / pieces, to = a + (b - a) * k / pieces;
      const Eigen::Vector3d p0 = coords(plane, from), p1 = coords(plane, to);
      if (d_ == NcDialect::heidenhain) {
        line("C " + std::string(1, names[lo]) + num(p1[lo]) + " " + names[hi] + num(p1[hi]) +
             (positive ? " DR+" : " DR-") + " F" + fixed(feed, 0));
      } else {
        const Eigen::Vector3d off = c - p0;  // I J K: centre relative to the block's start
        line(std::string(planes[n]) + (positive ? " G3 " : " G2 ") + names[lo] + num(p1[lo]) + " " +
             names[hi] + num(p1[hi]) + " " + centre_names[lo] + num(off[lo]) + " " +
             centre_names[hi] + num(off[hi]) + " F" + fixed(feed, 1));
      }
    }
  }

  void approach(const CircularRun& r) {
    const Eigen::Vector3d p = coords(r.plane, r.run_in_from_deg);
    comment("PLANE " + to_string(r.plane) + ": rapid to the start point at rotary zero");
    const std::string rot = tilt_ + num(0.0) + " " + rot_ + num(0.0);
    const std::string lin = "X" + num(p.x()) + " Y" + num(p.y()) + " Z" + num(p.z());
    if (d_ == NcDialect::heidenhain) {
      line("L " + rot + " R0 FMAX");
      line("L " + lin + " R0 FMAX");
      const int n = plane_normal(r.plane);
      const int lo = std::min((n + 1) % 3, (n + 2) % 3), hi = std::max((n + 1) % 3, (n + 2) % 3);
      const char* names = "XYZ";
      const Eigen::Vector3d c = centre();
      line("CC " + std::string(1, names[lo]) + num(c[lo]) + " " + names[hi] + num(c[hi]));
    } else {
      line("G0 " + rot);
      line("G0 " + lin);
    }
    if (o_.stop_to_mount) {
      comment("mount the ballbar between the pivot and the tool cup, start recording");
      line(d_ == NcDialect::heidenhain ? "STOP" : "M0");
    }
    angle_ = r.run_in_from_deg;
  }

  void header() {
    comment("rotacal ISO 230-4 circular tests of the linear axes - ballbar");
    comment("machine: " + to_string(plan_.machine) + ", rotary axes held at 0");
    comment("radius = ballbar length L0: " + fixed(plan_.radius, 4) + " mm");
    comment("centre = pivot: " + fixed(plan_.centre.x(), 4) + ", " + fixed(plan_.centre.y(), 4) +
            ", " + fixed(plan_.centre.z(), 4) + " mm");
    comment("data arc: " + general(plan_.span_deg) + " deg from " + general(plan_.start_deg) +
            " deg, run-in " + general(plan_.run_in_deg) + " deg, overshoot " +
            general(plan_.overshoot_deg) + " deg");
    std::string labels;
    for (const CircularRun& r : res_.runs) labels += (labels.empty() ? "" : ", ") + r.label;
    comment("runs: " + labels);
    comment(
        "angle from the plane's first axis towards its second: XY from +X, YZ from +Y, ZX from +Z");
    comment(
        "G3 / DR+ is counter-clockwise = a positive rotation about +Z [G17], +X [G19], +Y [G18]");
    if (d_ == NcDialect::linuxcnc && plan_.machine.has_head())
      comment("coordinates: machine axes of the controlled point - no tool length compensation");
    else if (o_.tool > 0)
      comment("tool " + std::to_string(o_.tool) + ": ballbar tool cup, length to its ball centre");
  }

  void prologue() {
    const nc_detail::Preamble preamble{"write_circular_nc_program", "program", "ROTACAL CIRCULAR",
                                       plan_.machine.has_head()};
    nc_detail::write_preamble(
        d_, o_, preamble, [this](const std::string& s) { line(s); }, [this] { header(); });
    // The rotary test's fanuc program calls the tool with TCPM on; this one calls it here.
    if (d_ == NcDialect::fanuc) line("G43 H" + std::to_string(o_.tool));
  }

  void epilogue() {
    switch (d_) {
      case NcDialect::linuxcnc:
        line("G17");
        line("M2");
        break;
      case NcDialect::heidenhain:
        line("M30");
        line("END PGM " + o_.program_name + " MM");
        break;
      case NcDialect::siemens:
        line("G17");
        line("M30");
        break;
      case NcDialect::fanuc:
        line("G17");
        line("M30");
        line("%");
        break;
    }
  }

  const CircularPlanResult& res_;
  const CircularTestPlan& plan_;
  NcDialect d_;
  NcProgramOptions o_;
  Eigen::Vector3d tv_;
  std::string tilt_, rot_;
  double angle_ = 0.0;
  std::vector<std::string> lines_;
};

}  // namespace

std::string write_circular_nc_program(const CircularPlanResult& result, NcDialect dialect,
                                      const NcProgramOptions& options) {
  if (result.runs.empty()) throw InvalidArgument("write_circular_nc_program: the plan has no runs");
  return CircularNcWriter(result, dialect, options).run();
}

}  // namespace rotacal

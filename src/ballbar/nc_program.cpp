// SPDX-License-Identifier: BSD-3-Clause
#include "rotacal/ballbar/nc_program.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <vector>

#include "../io/nc_words.hpp"
#include "rotacal/core/angles.hpp"
#include "rotacal/core/error.hpp"

namespace rotacal {

namespace {

// Two commanded poses closer than this (mm, deg) are the same: no block is written.
constexpr double kSamePose = 1e-9;

using nc_detail::fixed;
using nc_detail::general;

// The commanded state after a block.
struct Commanded {
  Eigen::Vector3d xyz;
  double tilt = 0.0, rot = 0.0;
  double time = 0.0;
};

bool same_pose(const Commanded& a, const PlannedSample& b) {
  return (a.xyz - b.xyz).norm() < kSamePose && std::abs(a.tilt - b.tilt_deg) < kSamePose &&
         std::abs(a.rot - b.rot_deg) < kSamePose;
}

class Writer {
 public:
  Writer(const BallbarPlan& plan, NcDialect d, const NcProgramOptions& o)
      : plan_(plan),
        d_(d),
        o_(o),
        tilt_(1, tilt_axis_letter(plan.setup.machine)),
        rot_(1, rot_axis_letter(plan.setup.machine)),
        zero_shift_(-tool_vector<double>(plan.setup.machine, 0.0)) {}

  std::string run() {
    prologue();
    const PlannedSample* first = first_sample();
    approach(*first);
    Commanded cur{first->xyz, first->tilt_deg, first->rot_deg, first->time};
    inverse_time(true);
    const auto& segs = plan_.segments;
    for (std::size_t i = 0; i < segs.size(); ++i) {
      const PlanSegment& seg = segs[i];
      segment_comment(seg);
      feed_factor_ = seg.feed_factor;
      if (seg.kind == SegmentKind::arc_transition && seg.arc.principal_axis >= 0) {
        tcp(false);
        arc_block(seg, end_time_of_arc(i), cur);
        continue;  // its points lie on the arc block; none is written
      }
      tcp(seg.kind != SegmentKind::arc_transition);
      for (const PlannedSample& s : seg.samples) {
        if (same_pose(cur, s)) continue;  // e.g. a test's first point, reached by an arc
        linear_block(s, s.time - cur.time);
        cur = {s.xyz, s.tilt_deg, s.rot_deg, s.time};
      }
    }
    epilogue();
    std::string out;
    for (std::size_t i = 0; i < lines_.size(); ++i) {
      if (d_ == NcDialect::heidenhain) out += std::to_string(i) + " ";
      out += lines_[i] + "\n";
    }
    return out;
  }

 private:
  bool is_tcp_dialect() const { return d_ != NcDialect::linuxcnc; }

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

  std::string feed_word(double dt_s) const {
    if (d_ == NcDialect::heidenhain)
      return "F" + fixed(plan_.setup.feed_mm_per_min * feed_factor_, 0);
    return "F" + fixed(60.0 / dt_s, 4);  // G93: reciprocal of the block time in minutes
  }

  // A block needs a positive duration (G93 feed = 1 / time); a hand-made or absurd plan whose
  // successive samples share a time is refused rather than written with an infinite feed.
  static void require_positive_time(double dt, double t) {
    if (!(dt > 0.0) || !std::isfinite(dt))
      throw InvalidArgument(
          "write_nc_program: the move ending at t = " + std::to_string(t) +
          " s takes no time (samples coincide in time: a plan with coordinates too "
          "large or steps too small for the feeds)");
  }

  const PlannedSample* first_sample() const {
    for (const PlanSegment& s : plan_.segments)
      if (!s.samples.empty()) return &s.samples.front();
    throw InvalidArgument("write_nc_program: the plan has no samples");
  }

  // Time at which an arc transition reaches its end: its own last point if that is the end,
  // else the next segment's first sample.
  double end_time_of_arc(std::size_t i) const {
    const PlanSegment& seg = plan_.segments[i];
    if (!seg.samples.empty() && (seg.samples.back().p_table - seg.arc.end).norm() < kSamePose)
      return seg.samples.back().time;
    ROTACAL_ASSERT(i + 1 < plan_.segments.size() && !plan_.segments[i + 1].samples.empty());
    return plan_.segments[i + 1].samples.front().time;
  }

  // Coordinates written for a sample: machine axes, or under TCPM the table-frame point that
  // the NOMINAL kinematics take to the planned machine axes (= p_table for a nominal plan).
  Eigen::Vector3d coords(const PlannedSample& s) const {
    if (!is_tcp_dialect() || !tcp_on_) return s.xyz;
    return ball_in_table(plan_.setup.machine, LocationErrors<double>(), s.angles_rad(), s.xyz);
  }

  std::string axes_words(const Eigen::Vector3d& p, double tilt, double rot) const {
    return "X" + num(p.x()) + " Y" + num(p.y()) + " Z" + num(p.z()) + " " + tilt_ + num(tilt) +
           " " + rot_ + num(rot);
  }

  void linear_block(const PlannedSample& s, double dt) {
    require_positive_time(dt, s.time);
    const std::string words = axes_words(coords(s), s.tilt_deg, s.rot_deg);
    if (d_ == NcDialect::heidenhain)
      line("L " + words + " R0 " + feed_word(dt));
    else
      line("G1 " + words + " " + feed_word(dt));
  }

  void arc_block(const PlanSegment& seg, double t_end, Commanded& cur) {
    const TransitionArc& a = seg.arc;
    const int n = a.principal_axis;  // 0: YZ (G19), 1: ZX (G18), 2: XY (G17)
    const bool positive = a.axis[n] > 0.0;
    // In-plane axes in the order of the plane (X,Y / Z,X / Y,Z); written in X, Y, Z order.
    const int i0 = (n + 1) % 3, i1 = (n + 2) % 3;
    const int lo = std::min(i0, i1), hi = std::max(i0, i1);
    const char* names = "XYZ";
    const char* centre_names = "IJK";
    // At rotary zero machine and table frames coincide (rotations by 0 for any errors), so the
    // planned arc, shifted by the tool vector on a head machine, is the machine-axis arc.
    ROTACAL_ASSERT((cur.xyz - (a.start + zero_shift_)).norm() < kSamePose && cur.tilt == 0.0 &&
                   cur.rot == 0.0);
    const Eigen::Vector3d e = a.end + zero_shift_, centre = a.center + zero_shift_;
    const double dt = t_end - cur.time;
    require_positive_time(dt, t_end);
    if (d_ == NcDialect::heidenhain) {
      line("CC " + std::string(1, names[lo]) + num(centre[lo]) + " " + names[hi] + num(centre[hi]));
      line("C " + std::string(1, names[lo]) + num(e[lo]) + " " + names[hi] + num(e[hi]) +
           (positive ? " DR+ " : " DR- ") + feed_word(dt));
    } else {
      static const char* planes[] = {"G19", "G18", "G17"};
      const Eigen::Vector3d off = centre - cur.xyz;  // I J K: centre relative to the start
      line(std::string(planes[n]) + (positive ? " G3 " : " G2 ") + names[lo] + num(e[lo]) + " " +
           names[hi] + num(e[hi]) + " " + centre_names[lo] + num(off[lo]) + " " + centre_names[hi] +
           num(off[hi]) + " " + feed_word(dt));
    }
    cur = {e, 0.0, 0.0, t_end};
  }

  void tcp(bool on) {
    if (!is_tcp_dialect() || on == tcp_on_) return;
    tcp_on_ = on;
    switch (d_) {
      case NcDialect::heidenhain:
        line(on ? "FUNCTION TCPM F CONT AXIS POS PATHCTRL AXIS" : "FUNCTION RESET TCPM");
        break;
      case NcDialect::siemens:
        line(on ? "TRAORI" : "TRAFOOF");
        break;
      case NcDialect::fanuc:
        // G43.4 and G43 are one modal group: G43 replaces TCP by plain length compensation
        // without a moment where the tool length is cancelled.
        line(on ? "G43.4 H" + std::to_string(o_.tool) : "G43 H" + std::to_string(o_.tool));
        break;
      case NcDialect::linuxcnc:
        break;
    }
  }

  void inverse_time(bool on) {
    if (d_ == NcDialect::heidenhain) return;
    line(on ? "G93" : "G94");
  }

  void header() {
    const BallbarSetup& s = plan_.setup;
    comment("rotacal single set-up ballbar test - Flynn et al. 2016");
    comment("machine: " + to_string(s.machine));
    comment("ballbar length L0: " + fixed(s.ballbar_length, 4) + " mm");
    comment("pivot: " + fixed(s.pivot.x(), 4) + ", " + fixed(s.pivot.y(), 4) + ", " +
            fixed(s.pivot.z(), 4) + " mm - nominal, table frame");
    std::string order;
    for (BallbarTest t : s.tests) order += (order.empty() ? "" : ", ") + test_label(t, s.machine);
    comment("test order: " + order);
    if (s.directions.size() > 1 || s.feed_factors.size() > 1) {
      std::string runs;
      for (SweepDirection d : s.directions) runs += (runs.empty() ? "" : ", ") + to_string(d);
      std::string feeds;
      for (double k : s.feed_factors)
        feeds += (feeds.empty() ? "" : ", ") + general(s.feed_mm_per_min * k);
      comment("each rotary test runs " + runs + " at " + feeds + " mm/min (labels _cw, _f<feed>)");
    }
    comment(tilt_ + " range: " + general(s.tilt_range_deg[0]) + " .. " +
            general(s.tilt_range_deg[1]) + " deg, C range: " + general(s.rot_range_deg[0]) +
            " .. " + general(s.rot_range_deg[1]) + " deg, step: " + general(s.step_deg) +
            " deg, radial C: " + to_string(s.radial_c_side));
    std::size_t n_test = 0;
    for (const PlanSegment& g : plan_.segments)
      if (g.kind == SegmentKind::test) n_test += g.samples.size();
    comment("samples: " + std::to_string(plan_.num_samples()) + " - " + std::to_string(n_test) +
            " in tests, planned duration: " + fixed(plan_.duration(), 1) + " s at " +
            general(s.feed_mm_per_min) + " mm/min, " + general(s.feed_deg_per_min) + " deg/min");
    if (plan_.compensation) {
      comment("kinematics: COMPENSATED with identified location errors - mm, rad:");
      const auto& names = location_error_names(s.machine);
      for (int i = 0; i < 8; ++i)
        comment("  " + names[static_cast<std::size_t>(i)] + " = " +
                general(plan_.compensation->v[i]));
    } else {
      comment("kinematics: nominal");
    }
    const MachineDescription& md = s.machine.description();
    comment("machine: " + md.name + " (" + md.configuration() + ")");
    comment(md.has_table() ? "datum: table frame, origin as formats.md fixes it (table axes at 0)"
                           : "datum: the machine's own zero (no table axes)");
    if (is_tcp_dialect())
      comment("coordinates: tool-cup ball centre in the table frame, under TCPM");
    else if (md.has_head())
      comment("coordinates: machine axes of the controlled point (the ball is " +
              general(md.pivot_length + md.tool_length) +
              " mm from it along the spindle) - rotacal inverse kinematics");
    else
      comment("coordinates: machine axes of the tool-cup ball centre - rotacal inverse kinematics");
    if (md.has_head() && !is_tcp_dialect())
      comment(
          "the head's pivot_length + tool_length is in the coordinates: no tool length "
          "compensation (G49) in this program");
    else if (o_.tool > 0)
      comment("tool " + std::to_string(o_.tool) + ": ballbar tool cup, length to its ball centre");
    comment("every feed block turns a rotary axis by at most " + general(s.step_deg) +
            " deg: shortest-way and linear rotary axes run it alike");
    comment("transitions: tool fixed on the table while rotary axes move; arcs about the pivot");
    comment("at rotary zero with TCPM off - the ballbar stays mounted throughout");
  }

  void prologue() {
    nc_detail::write_preamble(
        d_, o_,
        {"write_nc_program", "TCP program", "ROTACAL BALLBAR", plan_.setup.machine.has_head()},
        [this](const std::string& s) { line(s); }, [this] { header(); });
  }

  // Rapid to the first point, TCPM off, rotary axes first: no ballbar is mounted yet.
  void approach(const PlannedSample& s) {
    comment("approach: rotary axes, then linear axes, to the first point");
    const std::string rot = tilt_ + num(s.tilt_deg) + " " + rot_ + num(s.rot_deg);
    const std::string lin = "X" + num(s.xyz.x()) + " Y" + num(s.xyz.y()) + " Z" + num(s.xyz.z());
    if (d_ == NcDialect::heidenhain) {
      line("L " + rot + " R0 FMAX");
      line("L " + lin + " R0 FMAX");
    } else {
      line("G0 " + rot);
      if (d_ == NcDialect::fanuc)
        line("G0 G43 H" + std::to_string(o_.tool) + " " + lin);
      else
        line("G0 " + lin);
    }
    if (o_.stop_to_mount) {
      comment("mount the ballbar between the pivot and the tool cup, start recording");
      line(d_ == NcDialect::heidenhain ? "STOP" : "M0");
    }
  }

  void segment_comment(const PlanSegment& seg) {
    std::string text;
    switch (seg.kind) {
      case SegmentKind::test:
        text = "TEST " + seg.label + ": " + std::to_string(seg.samples.size()) + " samples";
        break;
      case SegmentKind::rotary_transition:
        text = "TRANSITION: rotary axes move, tool fixed on the table";
        break;
      case SegmentKind::arc_transition:
        text = "TRANSITION: arc of " + fixed(seg.arc.angle * 180.0 / kPi, 3) +
               " deg about the pivot at rotary zero, TCPM off";
        break;
    }
    comment(text);
  }

  void epilogue() {
    tcp(false);
    inverse_time(false);
    comment("end of test: remove the ballbar");
    switch (d_) {
      case NcDialect::linuxcnc:
        line("M2");
        break;
      case NcDialect::heidenhain:
        line("M30");
        line("END PGM " + o_.program_name + " MM");
        break;
      case NcDialect::siemens:
        line("M30");
        break;
      case NcDialect::fanuc:
        line("M30");
        line("%");
        break;
    }
  }

  const BallbarPlan& plan_;
  NcDialect d_;
  NcProgramOptions o_;
  std::string tilt_, rot_;
  // Machine axes minus table-frame ball at all rotary axes 0: zero on a table-table machine,
  // minus the tool vector on a machine with head axes (rotations by 0 are the identity for
  // any location errors).
  Eigen::Vector3d zero_shift_;
  bool tcp_on_ = false;
  double feed_factor_ = 1.0;  // of the segment being written (BallbarSetup::feed_factors)
  std::vector<std::string> lines_;
};

}  // namespace

std::string write_nc_program(const BallbarPlan& plan, NcDialect dialect,
                             const NcProgramOptions& options) {
  // A plan may be built by hand: every coordinate must be one a machine can be sent to.
  for (const PlanSegment& seg : plan.segments)
    for (const PlannedSample& s : seg.samples)
      if (!s.xyz.allFinite() || s.xyz.cwiseAbs().maxCoeff() > 1.0e5 || !std::isfinite(s.tilt_deg) ||
          !std::isfinite(s.rot_deg) || std::abs(s.rot_deg) > 1.0e6 ||
          std::abs(s.tilt_deg) > 360.0 || !std::isfinite(s.time))
        throw InvalidArgument("write_nc_program: a sample of " + seg.label +
                              " at t = " + std::to_string(s.time) +
                              " s has coordinates no machine can be sent to");
  return Writer(plan, dialect, options).run();
}

}  // namespace rotacal

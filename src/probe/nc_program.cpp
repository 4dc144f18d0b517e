// SPDX-License-Identifier: BSD-3-Clause
// The probing program of a touch-probe session and the reader of its LinuxCNC log
// (probe/nc_program.hpp). NC words and comments: src/io/nc_words.hpp, as the ballbar's
// and the circular tests' programs write them.
#include "rotacal/probe/nc_program.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <sstream>

#include "../io/nc_words.hpp"
#include "rotacal/core/angles.hpp"
#include "rotacal/core/error.hpp"
#include "rotacal/core/json_text.hpp"

namespace rotacal {

namespace {

void require_program(bool ok, const std::string& what) {
  if (!ok) throw InvalidArgument("plan probe: " + what);
}

// The rotary angle of chain axis k at a pose inside its limits (if any).
void check_limits(MachineType m, const RotaryAngles<double>& a_deg, int pose) {
  for (int k = 0; k < 2; ++k) {
    const RotaryAxis& ax = m.description().axis(k);
    const double v = k == m.rot_index() ? a_deg.rot : a_deg.tilt;
    if (ax.limits_deg && (v < (*ax.limits_deg)[0] - 1e-9 || v > (*ax.limits_deg)[1] + 1e-9))
      throw InvalidArgument(
          "plan probe: pose " + std::to_string(pose) + ": " + std::string(1, ax.name) + " " +
          nc_detail::general(v) + " deg is outside the axis limits " +
          nc_detail::general((*ax.limits_deg)[0]) + ".." + nc_detail::general((*ax.limits_deg)[1]));
  }
}

void check_travel(MachineType m, const Eigen::Vector3d& p, const std::string& what) {
  const auto& t = m.description().travel_mm;
  if (!t) return;
  for (int k = 0; k < 3; ++k)
    if (p[k] < (*t)(k, 0) - 1e-9 || p[k] > (*t)(k, 1) + 1e-9)
      throw InvalidArgument("plan probe: " + what + ": " + std::string(1, "XYZ"[k]) + " " +
                            nc_detail::general(p[k]) + " mm is outside the travel " +
                            nc_detail::general((*t)(k, 0)) + ".." + nc_detail::general((*t)(k, 1)));
}

// Distance from c to the segment [a, b].
double distance_to_segment(const Eigen::Vector3d& c, const Eigen::Vector3d& a,
                           const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double L2 = ab.squaredNorm();
  const double t = L2 > 0.0 ? std::clamp((c - a).dot(ab) / L2, 0.0, 1.0) : 0.0;
  return (a + t * ab - c).norm();
}

// The axis turning for `seconds` at the duty's speed (ThermalProgramDuty): whole revolutions of
// an endless axis, half forward and half back; strokes between lo and hi of an axis with
// limits. G91 for the endless axis' two moves, G90 after.
void write_duty_turning(MachineType m, const ThermalProgramDuty& t, double seconds, double lo,
                        double hi, int label, const std::function<void(const std::string&)>& line,
                        const std::function<std::string(double)>& num) {
  const double feed = 360.0 * t.speed_rpm;  // deg/min
  const std::string ax(1, t.axis), f = " F" + nc_detail::fixed(feed, 1);
  const RotaryAxis& axis =
      m.description().axis(t.axis == rot_axis_letter(m) ? m.rot_index() : m.tilt_index());
  if (t.axis != tilt_axis_letter(m) && !axis.limits_deg) {
    const long half = std::lround(0.5 * t.speed_rpm * seconds / 60.0);  // revolutions each way
    if (half < 1) return;
    line("G91");
    line("G1 " + ax + num(360.0 * static_cast<double>(half)) + f);
    line("G1 " + ax + num(-360.0 * static_cast<double>(half)) + f);
    line("G90");
    return;
  }
  const long pairs = std::lround(feed * seconds / 60.0 / (2.0 * (hi - lo)));
  if (pairs < 1) return;
  const std::string o = "O" + std::to_string(label);
  line("G1 " + ax + num(lo) + f);
  line(o + " repeat [" + std::to_string(pairs) + "]");
  line("G1 " + ax + num(hi) + f);
  line("G1 " + ax + num(lo) + f);
  line(o + " endrepeat");
}

}  // namespace

std::vector<double> ThermalProgramDuty::epoch_starts() const {
  std::vector<double> out;
  for (int e = 0; interval_s > 0.0 && e * interval_s <= heat_s + cool_s + 1e-9; ++e)
    out.push_back(e * interval_s);
  return out;
}

std::vector<ProbeMove> probe_moves(MachineType m, const ProbePattern& P,
                                   const ProbeProgramOptions& o, double* retract_z) {
  const double r = 0.5 * (P.sphere_diameter + P.stylus_diameter);
  require_program(P.sphere_diameter > 0.0 && P.stylus_diameter > 0.0,
                  "sphere and stylus diameters must be > 0");
  require_program(!P.poses_deg.empty() && (!P.directions.empty() || !P.pose_directions.empty()),
                  "the pattern has no poses or no directions");
  require_program(P.pose_directions.empty() || P.pose_directions.size() == P.poses_deg.size(),
                  "the per-pose directions must hold one list per pose");
  require_program(o.approach_mm > 0.0 && o.clearance_mm > 0.0,
                  "approach and clearance must be > 0 mm");
  require_program(o.overtravel_mm > 0.0 && o.overtravel_mm < r,
                  "overtravel must be in (0, " + nc_detail::general(r) + ") mm");
  require_program(o.probe_feed_mm_per_min > 0.0 && o.feed_mm_per_min > 0.0, "feeds must be > 0");
  std::vector<ProbeMove> out;
  std::vector<Eigen::Vector3d> centres;
  double top = -1e300;
  for (std::size_t k = 0; k < P.poses_deg.size(); ++k) {
    const int pose = static_cast<int>(k) + 1;
    check_limits(m, P.poses_deg[k], pose);
    const RotaryAngles<double> a{P.poses_deg[k].tilt * kDeg, P.poses_deg[k].rot * kDeg};
    const Eigen::Vector3d c =
        inverse(m, LocationErrors<double>(), a, P.sphere).xyz;  // as simulate_probe
    top = std::max(top, c.z() + r);
    const std::vector<Eigen::Vector3d>& dirs = P.directions_at(k);
    require_program(!dirs.empty(), "pose " + std::to_string(pose) + " has no approach direction");
    for (std::size_t j = 0; j < dirs.size(); ++j) {
      require_program(dirs[j].norm() > 0.0, "a zero approach direction");
      ProbeMove mv;
      mv.pose = pose;
      mv.touch = static_cast<int>(j) + 1;
      mv.angles_deg = P.poses_deg[k];
      mv.n = dirs[j].normalized();
      mv.start = c - (r + o.approach_mm) * mv.n;
      mv.target = c - (r - o.overtravel_mm) * mv.n;
      out.push_back(mv);
      centres.push_back(c);
    }
  }
  // The rotary axes turn between poses with the tool on the retract plane: it lies above the
  // sphere all along those turns (G0 moves the axes in proportion: sampled every 0.5 deg).
  for (std::size_t k = 1; k < P.poses_deg.size(); ++k) {
    const RotaryAngles<double>& a0 = P.poses_deg[k - 1];
    const RotaryAngles<double>& a1 = P.poses_deg[k];
    const int steps = 1 + static_cast<int>(2.0 * std::max(std::abs(a1.tilt - a0.tilt),
                                                          std::abs(a1.rot - a0.rot)));
    for (int i = 1; i < steps; ++i) {
      const double f = static_cast<double>(i) / steps;
      const RotaryAngles<double> a{(a0.tilt + f * (a1.tilt - a0.tilt)) * kDeg,
                                   (a0.rot + f * (a1.rot - a0.rot)) * kDeg};
      top = std::max(top, inverse(m, LocationErrors<double>(), a, P.sphere).xyz.z() + r);
    }
  }
  const double z = top + o.clearance_mm;
  for (std::size_t i = 0; i < out.size(); ++i) {
    const ProbeMove& mv = out[i];
    const std::string where =
        "pose " + std::to_string(mv.pose) + ", touch " + std::to_string(mv.touch);
    const Eigen::Vector3d above(mv.start.x(), mv.start.y(), z);
    if (distance_to_segment(centres[i], mv.start, above) <= r)
      throw InvalidArgument(
          "plan probe: " + where +
          ": the way up from the start of the touch passes through "
          "the sphere (approach along this direction from farther out, or from above)");
    for (const Eigen::Vector3d& p : {mv.start, mv.target, above}) check_travel(m, p, where);
  }
  if (retract_z) *retract_z = z;
  return out;
}

std::string write_probe_nc_program(MachineType m, const ProbePattern& P, NcDialect d,
                                   const ProbeProgramOptions& o) {
  if (d != NcDialect::linuxcnc)
    throw InvalidArgument(
        "plan probe: no checkable probing words are implemented for the " + to_string(d) +
        " dialect (its probing cycles cannot be checked without its controller); use linuxcnc");
  double z = 0.0;
  const std::vector<ProbeMove> moves = probe_moves(m, P, o, &z);
  std::vector<std::string> lines;
  const auto line = [&](const std::string& s) { lines.push_back(s); };
  const auto comment = [&](const std::string& text) {
    for (const std::string& l : comment_lines(CommentDialect::linuxcnc, text)) line(l);
  };
  const auto num = [&](double v) { return nc_detail::fixed(v, o.decimals); };
  const std::string tilt(1, tilt_axis_letter(m)), rot(1, rot_axis_letter(m));
  NcProgramOptions nc;
  nc.decimals = o.decimals;
  nc.tool = o.tool;
  nc_detail::Preamble pre{"write_probe_nc_program", "probing program", "ROTACAL PROBE",
                          m.has_head()};
  nc_detail::write_preamble(d, nc, pre, line, [&] {
    comment("rotacal touch-probe program, machine " + to_string(m) + " (machine axes)");
    comment("sphere " + nc_detail::general(P.sphere.x()) + ", " + nc_detail::general(P.sphere.y()) +
            ", " + nc_detail::general(P.sphere.z()) + " mm (table frame), D " +
            nc_detail::general(P.sphere_diameter) + " mm, stylus d " +
            nc_detail::general(P.stylus_diameter) + " mm");
    comment((P.pose_directions.empty() ? std::to_string(P.poses_deg.size()) + " poses x " +
                                             std::to_string(P.directions.size()) + " touches"
                                       : std::to_string(P.poses_deg.size()) + " poses, " +
                                             std::to_string(P.touch_count()) +
                                             " touches along each pose's own directions") +
            "; the log holds one line per touch: pose touch X Y Z (latched)");
    comment(
        "start with the stylus clear of the sphere: Z goes to the retract plane, then the rotary "
        "axes turn");
  });
  // (LOGOPEN,name) is one comment-like word of the line: no byte that ends or changes it, and
  // the line within what LinuxCNC reads (254 characters).
  const bool control = std::any_of(o.log_file.begin(), o.log_file.end(), [](char c) {
    const auto u = static_cast<unsigned char>(c);
    return u < 0x20 || u == 0x7F;
  });
  if (o.log_file.empty() || control || o.log_file.find_first_of("()") != std::string::npos)
    throw InvalidArgument("the probe program's --log-file '" + printable(o.log_file) +
                          "': the log file name must be non-empty, without '(', ')' or control "
                          "bytes (line ends, escapes)");
  if (o.log_file.size() > kMaxLogFileName)
    throw InvalidArgument("the probe program's --log-file: " + std::to_string(o.log_file.size()) +
                          " characters; (LOGOPEN,...) must stay within LinuxCNC's 254-character "
                          "line, so at most " +
                          std::to_string(kMaxLogFileName));
  line("(LOGOPEN," + o.log_file + ")");
  line("G0 Z" + num(z));
  const std::string probe_feed = "F" + nc_detail::fixed(o.probe_feed_mm_per_min, 1);
  const std::string feed = "F" + nc_detail::fixed(o.feed_mm_per_min, 1);
  // A thermal test: the pattern once per epoch, the duty between (ThermalProgramDuty).
  std::vector<double> epochs{0.0};
  double lo = 0.0, hi = 0.0, epoch_s = P.pose_dt_s * static_cast<double>(P.poses_deg.size());
  if (o.thermal) {
    const ThermalProgramDuty& t = *o.thermal;
    require_program(
        t.axis == tilt_axis_letter(m) || t.axis == rot_axis_letter(m),
        "thermal duty: machine " + to_string(m) + " has no axis " + std::string(1, t.axis));
    require_program(t.speed_rpm > 0.0 && t.speed_rpm <= t.max_speed_rpm,
                    "thermal duty: --speed " + nc_detail::general(t.speed_rpm) +
                        " rev/min must be > 0 and at most --max-speed " +
                        nc_detail::general(t.max_speed_rpm) + " rev/min");
    require_program(t.interval_s > epoch_s && t.heat_s >= 0.0 && t.cool_s >= 0.0,
                    "thermal duty: --interval " + nc_detail::general(t.interval_s) +
                        " s must be longer than an epoch (" + nc_detail::general(epoch_s) +
                        " s: " + std::to_string(P.poses_deg.size()) + " poses)");
    epochs = t.epoch_starts();
    lo = 1e300, hi = -1e300;  // the swing of an axis with limits: the pattern's own range
    for (const RotaryAngles<double>& a : P.poses_deg) {
      const double v = t.axis == tilt_axis_letter(m) ? a.tilt : a.rot;
      lo = std::min(lo, v), hi = std::max(hi, v);
    }
    const RotaryAxis& ax =
        m.description().axis(t.axis == rot_axis_letter(m) ? m.rot_index() : m.tilt_index());
    require_program((t.axis != tilt_axis_letter(m) && !ax.limits_deg) || hi > lo,
                    "thermal duty: axis " + std::string(1, t.axis) +
                        " tilts or has limits, so it swings back and forth between the epoch "
                        "poses' "
                        "angles of it, which must differ");
  }
  const int n_poses = static_cast<int>(P.poses_deg.size());
  for (std::size_t e = 0; e < epochs.size(); ++e) {
    const int first = static_cast<int>(e) * n_poses;  // pose numbers run on over the epochs
    if (o.thermal)
      comment("epoch " + std::to_string(e + 1) + " at " + nc_detail::general(epochs[e]) + " s");
    int pose = 0;
    for (const ProbeMove& mv : moves) {
      if (mv.pose != pose) {
        pose = mv.pose;
        comment("pose " + std::to_string(first + pose) + ": " + tilt + " " +
                nc_detail::general(mv.angles_deg.tilt) + ", " + rot + " " +
                nc_detail::general(mv.angles_deg.rot) + " deg (turned on the retract plane)");
        line("G0 " + tilt + num(mv.angles_deg.tilt) + " " + rot + num(mv.angles_deg.rot));
      }
      line("G0 X" + num(mv.start.x()) + " Y" + num(mv.start.y()));
      line("G1 Z" + num(mv.start.z()) + " " + feed);
      line("G38.2 X" + num(mv.target.x()) + " Y" + num(mv.target.y()) + " Z" + num(mv.target.z()) +
           " " + probe_feed);
      line("(LOG," + std::to_string(first + mv.pose) + " " + std::to_string(mv.touch) +
           " #5061 #5062 #5063)");
      line("G1 X" + num(mv.start.x()) + " Y" + num(mv.start.y()) + " Z" + num(mv.start.z()) + " " +
           feed);
      line("G0 Z" + num(z));
    }
    if (!o.thermal || e + 1 == epochs.size()) continue;
    // The duty until the next epoch: turning while t < heat_s, at rest after.
    const ThermalProgramDuty& t = *o.thermal;
    const double from = epochs[e] + epoch_s, to = epochs[e + 1];
    const double turn = std::max(0.0, std::min(to, t.heat_s) - from);
    if (turn > 0.0) {
      comment("duty: " + std::string(1, t.axis) + " at " + nc_detail::general(t.speed_rpm) +
              " rev/min for " + nc_detail::general(turn) + " s");
      write_duty_turning(m, t, turn, lo, hi, 100 + static_cast<int>(e), line, num);
    }
    if (to - from - turn > 0.0) line("G4 P" + nc_detail::fixed(to - from - turn, 1));
  }
  line("(LOGCLOSE)");
  line("M2");
  std::string out;
  for (const std::string& l : lines) out += l + "\n";
  return out;
}

ProbeSession read_linuxcnc_probe_log(const std::string& path, const ProbeSession& plan,
                                     double max_off_line_mm) {
  std::ifstream in(path);
  if (!in) throw IoError("cannot read " + path);
  ProbeSession out = plan;
  std::string text;
  std::size_t row = 0;
  int line_no = 0;
  // The pose and touch numbers the program wrote for row i (probe_moves order).
  int pose = 0, touch = 0;
  std::string last_pose;
  while (std::getline(in, text)) {
    ++line_no;
    if (!text.empty() && text.back() == '\r') text.pop_back();
    if (line_no == 1 && text.size() >= 2 &&
        (text.compare(0, 2, "\xFF\xFE") == 0 || text.compare(0, 2, "\xFE\xFF") == 0))
      throw ParseError(path, 1, 1,
                       "the log is UTF-16 text; rotacal reads the controller's log as ASCII "
                       "(save it as UTF-8 or ASCII)");
    if (text.find_first_not_of(" \t") == std::string::npos) continue;
    std::istringstream fields(text);
    double p = 0, t = 0;
    Eigen::Vector3d xyz;
    std::string extra;
    if (!(fields >> p >> t >> xyz.x() >> xyz.y() >> xyz.z()) || (fields >> extra) ||
        !xyz.allFinite())
      throw ParseError(path, line_no, 1,
                       "expected 'pose touch X Y Z' (five finite numbers within a double's range), "
                       "got '" +
                           printable(text) + "'");
    if (row >= plan.samples.size())
      throw ParseError(path, line_no, 1,
                       "more touches than the plan's " + std::to_string(plan.samples.size()));
    const ProbeSample& s = plan.samples[row];
    if (s.pose != last_pose) ++pose, touch = 0, last_pose = s.pose;
    ++touch;
    if (p != pose || t != touch)
      throw ParseError(path, line_no, 1,
                       "touch " + nc_detail::general(p) + " " + nc_detail::general(t) +
                           " where the plan has pose " + std::to_string(pose) + ", touch " +
                           std::to_string(touch) + " (a touch missing or out of order)");
    // G38.2 moves along the commanded line: a latch off it is another touch, or a typo.
    const Eigen::Vector3d d = xyz - s.xyz, n = s.n.normalized();
    const double off = (d - d.dot(n) * n).norm();
    if (!(off <= max_off_line_mm))
      throw ParseError(path, line_no, 1,
                       "pose " + std::to_string(pose) + ", touch " + std::to_string(touch) +
                           " latched " + nc_detail::general(off) +
                           " mm off its commanded line (the plan's X, Y, Z along its nx, ny, nz), "
                           "more than " +
                           nc_detail::general(max_off_line_mm) +
                           " mm: not the touch the program commanded, or a mistyped value");
    out.samples[row++].xyz = xyz;
  }
  if (row != plan.samples.size())
    throw ParseError(path, line_no, 1,
                     std::to_string(row) + " touches logged, the plan has " +
                         std::to_string(plan.samples.size()));
  out.noise_um.reset();
  out.metadata.erase(std::remove_if(out.metadata.begin(), out.metadata.end(),
                                    [](const auto& kv) { return kv.first == "noise_um"; }),
                     out.metadata.end());
  return out;
}

}  // namespace rotacal

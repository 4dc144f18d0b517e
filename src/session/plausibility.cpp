// SPDX-License-Identifier: BSD-3-Clause
// Plausibility of sessions against the nominal kinematics, with the likely cause of a misfit named.
#include "rotacal/session/plausibility.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "rotacal/core/angles.hpp"
#include "rotacal/core/error.hpp"
#include "rotacal/kinematics/machine_description.hpp"
#include "rotacal/session/probe_session.hpp"

namespace rotacal {

namespace {

constexpr double kInch = 25.4;

std::string fmt(double v, int digits = 4) {
  char b[48];
  std::snprintf(b, sizeof b, "%.*g", digits, v);
  return b;
}

double median_of(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

template <typename Sample>
void spans(const std::vector<Sample>& samples, double& tilt, double& rot, double& max_abs) {
  double t0 = 1e300, t1 = -1e300, r0 = 1e300, r1 = -1e300;
  max_abs = 0.0;
  for (const Sample& s : samples) {
    t0 = std::min(t0, s.tilt_deg), t1 = std::max(t1, s.tilt_deg);
    r0 = std::min(r0, s.rot_deg), r1 = std::max(r1, s.rot_deg);
    max_abs = std::max({max_abs, std::abs(s.tilt_deg), std::abs(s.rot_deg)});
  }
  tilt = t1 - t0;
  rot = r1 - r0;
}

// Angles read as radians instead of degrees: if the file's angles were radians, deg -> rad
// conversion must be skipped, i.e. the value in the file is used directly as rad.
RotaryAngles<double> angles_as(double tilt, double rot, bool file_is_radians) {
  const double k = file_is_radians ? 1.0 : kDeg;
  return {tilt * k, rot * k};
}

[[noreturn]] void refuse(const std::string& source, const std::string& what) {
  throw InvalidArgument(source + ": implausible session: " + what);
}

void check_spans(const std::string& source, double tilt_span, double rot_span,
                 const PlausibilityOptions& o) {
  if (tilt_span < o.min_rotary_span_deg && rot_span < o.min_rotary_span_deg)
    refuse(source, "all rotary angles equal: the axes never move (tilt spans " + fmt(tilt_span) +
                       " deg, C " + fmt(rot_span) +
                       " deg); the rotary axes' errors cannot be seen");
}

}  // namespace

PlausibilityReport check_plausible(const BallbarSession& s, const std::string& source,
                                   const PlausibilityOptions& o) {
  if (s.samples.empty()) refuse(source, "no samples");
  PlausibilityReport rep;
  const double L0 = s.ballbar_length;
  if (L0 < o.min_ballbar_length_mm)
    refuse(source, "ballbar_length " + fmt(L0) +
                       " mm: no ballbar is that short; lengths look like inches (" +
                       fmt(L0 * kInch) + " mm?)");
  double max_abs_angle = 0.0;
  spans(s.samples, rep.tilt_span_deg, rep.rot_span_deg, max_abs_angle);
  check_spans(source, rep.tilt_span_deg, rep.rot_span_deg, o);

  const LocationErrors<double> nominal;
  // Nominal length of each sample, with the angles as degrees (the format) and, to name the
  // cause of a misfit, as radians.
  std::vector<double> dev_deg, dev_rad, measured, commanded;
  dev_deg.reserve(s.samples.size());
  for (const BallbarSample& b : s.samples) {
    // The nominal bar: tool ball of the command against the nominal pivot (any machine).
    auto bar = [&](bool radians) {
      const RotaryAngles<double> a = angles_as(b.tilt_deg, b.rot_deg, radians);
      return (tool_ball(s.machine, nominal, a, b.xyz) - forward(s.machine, nominal, a, s.pivot))
          .norm();
    };
    const double nominal_deg = bar(false), nominal_rad = bar(true);
    dev_deg.push_back(std::abs(b.length - nominal_deg));
    dev_rad.push_back(std::abs(b.length - nominal_rad));
    measured.push_back(b.length);
    commanded.push_back(nominal_deg);
  }
  rep.median_deviation_mm = median_of(dev_deg);
  const auto worst = std::max_element(dev_deg.begin(), dev_deg.end());
  rep.max_deviation_mm = *worst;
  rep.worst_sample = static_cast<std::size_t>(worst - dev_deg.begin());
  // Name the likely cause, most specific first. L0 itself must agree with the data too: the
  // fit would otherwise absorb a wrong L0 into the length offset it cannot separate.
  const double med_len = median_of(measured), med_cmd = median_of(commanded);
  const double limit = o.max_length_deviation_mm;
  if (rep.max_deviation_mm <= limit && std::abs(med_len - L0) <= limit) return rep;
  if (max_abs_angle <= 2.0 * kPi + 1e-9 && median_of(dev_rad) <= limit &&
      rep.median_deviation_mm > limit)
    refuse(source,
           "angles look like radians: every angle is within +-2 pi, and read as radians they fit "
           "the commanded positions (median deviation " +
               fmt(median_of(dev_rad) * 1e3, 3) + " um) while read as degrees they do not (" +
               fmt(rep.median_deviation_mm, 4) + " mm); the format wants degrees");
  if (std::abs(med_len * kInch - med_cmd) <= limit)
    refuse(source, "lengths look like inches: the measured lengths are ~" + fmt(med_len) +
                       " while the commanded positions are ~" + fmt(med_cmd) +
                       " mm from the pivot (" + fmt(med_len) + " in = " + fmt(med_len * kInch) +
                       " mm); the format wants mm");
  if (std::abs(med_len - L0) > limit && std::abs(med_len - med_cmd) <= limit)
    refuse(
        source,
        "ballbar_length " + fmt(L0) + " but the data say ~" + fmt(med_len) +
            " mm (measured lengths and commanded positions agree on it): fix '# ballbar_length:'");
  if (std::abs(med_cmd - L0) <= limit && std::abs(med_len - L0) > limit)
    refuse(source, "ballbar_length " + fmt(L0) +
                       " and the commanded positions agree, but the measured lengths "
                       "are ~" +
                       fmt(med_len) + " mm: a length column in other units or of another ballbar?");
  if (std::abs(med_cmd - L0) > limit && std::abs(med_len - L0) <= limit)
    refuse(source, "the commanded positions are ~" + fmt(med_cmd) +
                       " mm from the nominal pivot, not L0 = " + fmt(L0) +
                       " mm: wrong '# pivot:', wrong machine, or the positions are not the "
                       "commanded machine axes");
  const BallbarSample& w = s.samples[rep.worst_sample];
  refuse(source, "sample " + std::to_string(rep.worst_sample) + " (test " + w.test + ", time " +
                     fmt(w.time, 8) + " s): measured length " + fmt(w.length, 8) +
                     " mm, nominal kinematics give " + fmt(commanded[rep.worst_sample], 8) +
                     " mm; " + fmt(rep.max_deviation_mm) + " mm apart, more than the " +
                     fmt(limit) +
                     " mm a machine's errors and set-up explain (rotacal's --max-deviation or "
                     "PlausibilityOptions::max_length_deviation_mm widens it)");
}

PlausibilityReport check_plausible(const RtestSession& s, const std::string& source,
                                   const PlausibilityOptions& o) {
  if (s.samples.empty()) refuse(source, "no samples");
  PlausibilityReport rep;
  double max_abs_angle = 0.0;
  spans(s.samples, rep.tilt_span_deg, rep.rot_span_deg, max_abs_angle);
  check_spans(source, rep.tilt_span_deg, rep.rot_span_deg, o);
  const LocationErrors<double> nominal;
  std::vector<double> dev_deg, dev_rad, dev_inch;
  for (const RtestSample& r : s.samples) {
    const auto it = s.nests.find(r.setup);
    if (it == s.nests.end()) refuse(source, "setup '" + r.setup + "' has no nest");
    const Eigen::Vector3d& q = it->second;
    // Commanded linear axes against where the nominal machine commands the nest (any machine).
    auto off = [&](const Eigen::Vector3d& xyz, bool radians) {
      return (xyz - inverse(s.machine, nominal, angles_as(r.tilt_deg, r.rot_deg, radians), q).xyz)
          .norm();
    };
    dev_deg.push_back(off(r.xyz, false));
    dev_rad.push_back(off(r.xyz, true));
    dev_inch.push_back(off(r.xyz * kInch, false));
    if (r.d && r.d->cwiseAbs().maxCoeff() > o.max_displacement_mm) {
      const std::size_t i = dev_deg.size() - 1;
      refuse(source,
             "pose " + std::to_string(i) + " (setup " + r.setup + ", time " + fmt(r.time, 8) +
                 " s): displacement (" + fmt(r.d->x()) + ", " + fmt(r.d->y()) + ", " +
                 fmt(r.d->z()) + ") mm exceeds " + fmt(o.max_displacement_mm) +
                 " mm, far more than a machine's errors: displacements in um instead of mm, or "
                 "a probe out of range? (PlausibilityOptions::max_displacement_mm widens it)");
    }
  }
  rep.median_deviation_mm = median_of(dev_deg);
  const auto worst = std::max_element(dev_deg.begin(), dev_deg.end());
  rep.max_deviation_mm = *worst;
  rep.worst_sample = static_cast<std::size_t>(worst - dev_deg.begin());
  const double limit = o.max_position_deviation_mm;
  if (rep.max_deviation_mm <= limit) return rep;
  if (max_abs_angle <= 2.0 * kPi + 1e-9 && median_of(dev_rad) <= limit)
    refuse(
        source,
        "angles look like radians: every angle is within +-2 pi, and read as radians the commanded "
        "positions follow the nests (median " +
            fmt(median_of(dev_rad) * 1e3, 3) +
            " um) while read as degrees they do not; the format wants degrees");
  if (median_of(dev_inch) <= limit)
    refuse(source,
           "positions look like inches: times 25.4 the commanded positions follow the nests; the "
           "format wants mm");
  const RtestSample& w = s.samples[rep.worst_sample];
  refuse(
      source,
      "pose " + std::to_string(rep.worst_sample) + " (setup " + w.setup + ", time " +
          fmt(w.time, 8) + " s): the commanded position is " + fmt(rep.max_deviation_mm) +
          " mm from where the nominal axes carry nest." + w.setup + ", more than the " +
          fmt(limit) +
          " mm a machine's errors explain: wrong nest metadata, wrong machine, or positions that "
          "are not the commanded axes (rotacal's --max-deviation or "
          "PlausibilityOptions::max_position_deviation_mm widens it)");
}

namespace {

// |distance of the nominal stylus-tip centre from the nominal sphere centre - trigger radius|
// of every touch, the angles read as the file says or as a careless file may hold them.
struct ProbeReading {
  bool radians = false;  // the file's angles taken as radians
  bool swapped = false;  // the tilt and rotary columns exchanged
};

std::vector<double> touch_distances(const ProbeSession& s, MachineType m, ProbeReading how) {
  const LocationErrors<double> nominal;
  std::vector<double> out;
  out.reserve(s.samples.size());
  for (const ProbeSample& t : s.samples) {
    const double tilt = how.swapped ? t.rot_deg : t.tilt_deg;
    const double rot = how.swapped ? t.tilt_deg : t.rot_deg;
    const RotaryAngles<double> a = angles_as(tilt, rot, how.radians);
    out.push_back((tool_ball(m, nominal, a, t.xyz) - forward(m, nominal, a, s.sphere)).norm());
  }
  return out;
}

// How many touches lie farther than `limit` from `radius` about the nominal sphere centre.
std::size_t off_sphere(const std::vector<double>& dist, double radius, double limit) {
  return static_cast<std::size_t>(std::count_if(
      dist.begin(), dist.end(), [&](double d) { return !(std::abs(d - radius) <= limit); }));
}

}  // namespace

PlausibilityReport check_plausible(const ProbeSession& s, const std::string& source,
                                   const PlausibilityOptions& o) {
  if (s.samples.empty()) refuse(source, "no touches");
  PlausibilityReport rep;
  double max_abs_angle = 0.0;
  spans(s.samples, rep.tilt_span_deg, rep.rot_span_deg, max_abs_angle);
  check_spans(source, rep.tilt_span_deg, rep.rot_span_deg, o);
  const double R = s.trigger_radius();
  if (!(R > 0.0) || !std::isfinite(R))
    refuse(source, "trigger radius (sphere_diameter + stylus_diameter) / 2 = " + fmt(R) +
                       " mm: a touch needs a sphere and a stylus of positive size");
  // Every touch: the nominal stylus-tip centre at the trigger lies the trigger radius from the
  // nominal sphere centre, to within the sphere's placement and the machine's errors.
  const std::vector<double> dist = touch_distances(s, s.machine, {});
  std::vector<double> dev;
  for (double d : dist) dev.push_back(std::abs(d - R));
  rep.median_deviation_mm = median_of(dev);
  const auto worst = std::max_element(dev.begin(), dev.end());
  rep.max_deviation_mm = *worst;
  rep.worst_sample = static_cast<std::size_t>(worst - dev.begin());
  const double limit = o.max_position_deviation_mm;
  if (rep.max_deviation_mm <= limit) return rep;
  // The likely cause, most specific first: a reading of the file under which every touch but
  // a few outliers (at most 1 in 20) lies on the sphere.
  const std::size_t allowed = std::max<std::size_t>(1, dist.size() / 20);
  const bool most_fail = off_sphere(dist, R, limit) > allowed;
  auto fits = [&](MachineType m, ProbeReading how) {
    return off_sphere(touch_distances(s, m, how), R, limit) <= allowed;
  };
  if (most_fail && max_abs_angle <= 2.0 * kPi + 1e-9 && fits(s.machine, {true, false}))
    refuse(source,
           "angles look like radians: every angle is within +-2 pi, and read as radians the "
           "touches lie on the sphere while read as degrees they do not (median " +
               fmt(rep.median_deviation_mm) + " mm off); the format wants degrees");
  if (most_fail && fits(s.machine, {false, true}))
    refuse(source, std::string("the ") + tilt_axis_letter(s.machine) + " and " +
                       rot_axis_letter(s.machine) +
                       " columns look swapped: exchanged, the touches lie on the sphere (median " +
                       fmt(rep.median_deviation_mm) + " mm off as the file has them)");
  if (most_fail)
    for (const std::string& name : builtin_machine_names()) {
      const MachineType other = parse_machine_type(name);
      if (other == s.machine || !fits(other, {})) continue;
      refuse(source, "the touches fit a " + name + " machine, not the " + to_string(s.machine) +
                         " the file names (median " + fmt(rep.median_deviation_mm) +
                         " mm off): fix '# machine:'");
    }
  const double M = median_of(dist);
  if (std::abs(M - R) > limit && off_sphere(dist, M, limit) <= allowed)
    refuse(source, "the touches lie ~" + fmt(M) +
                       " mm from the nominal sphere centre, but the trigger radius "
                       "(sphere_diameter " +
                       fmt(s.sphere_diameter) + " + stylus_diameter " + fmt(s.stylus_diameter) +
                       ") / 2 is " + fmt(R) +
                       " mm: a wrong '# sphere_diameter:' or '# stylus_diameter:' (together ~" +
                       fmt(2.0 * M) + " mm by the data)");
  const ProbeSample& w = s.samples[rep.worst_sample];
  refuse(source,
         "touch " + std::to_string(rep.worst_sample) + " (pose " + w.pose + ", time " +
             fmt(w.time, 8) + " s) at (" + fmt(w.xyz.x(), 8) + ", " + fmt(w.xyz.y(), 8) + ", " +
             fmt(w.xyz.z(), 8) + ") is " + fmt(rep.max_deviation_mm) +
             " mm off the nominal sphere, more than the " + fmt(limit) + " mm its placement and " +
             "a machine's errors explain" +
             (most_fail ? ", and so are most touches (median " + fmt(rep.median_deviation_mm) +
                              " mm): wrong '# sphere:', wrong machine, or positions that are "
                              "not the latched stylus-tip centre"
                        : ": an outlier touch (a false trigger or a mistyped value)") +
             " (rotacal's --max-deviation or PlausibilityOptions::max_position_deviation_mm "
             "widens it)");
}

void check_model_machine(MachineType model_machine, MachineType session_machine,
                         const std::string& model_source) {
  if (model_machine != session_machine)
    throw InvalidArgument("session machine " + to_string(session_machine) + ", model " +
                          to_string(model_machine) + " (" + model_source +
                          "): a model applies only to its own machine");
}

}  // namespace rotacal

// SPDX-License-Identifier: BSD-3-Clause
#include "rotacal/circular/analysis.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numeric>

#include "rotacal/core/angles.hpp"
#include "rotacal/core/error.hpp"
#include "rotacal/fit/circle.hpp"

namespace rotacal {

namespace {

constexpr double kRad = 180.0 / kPi;
// The shortest data arc whose circle is determined: the least-squares centre of an arc of
// span s moves ~ noise / (1 - cos(s/2)) along its bisector, so a 2-5 deg arc (issue 32) put the
// centre millimetres off and the radius deviation hundreds of um while looking like a result.
constexpr double kMinCircularSpanDeg = 30.0;

// "circular_XY_ccw[_suffix]" -> plane, direction, suffix; false if not "circular_".
bool parse_label(const std::string& label, CircularPlane* plane, CircularDirection* dir,
                 std::string* suffix) {
  const std::string prefix = "circular_";
  if (label.compare(0, prefix.size(), prefix) != 0) return false;
  const std::string rest = label.substr(prefix.size());
  const auto bad = [&]() {
    return InvalidArgument("test " + label +
                           ": a circular run's label is circular_<XY|YZ|ZX>_<ccw|cw>[_f<feed>]");
  };
  if (rest.size() < 4 || rest[2] != '_') throw bad();
  try {
    *plane = parse_circular_plane(rest.substr(0, 2));
  } catch (const InvalidArgument&) {
    throw bad();
  }
  const std::string tail = rest.substr(3);
  const std::size_t us = tail.find('_');
  const std::string d = tail.substr(0, us);
  if (d != "ccw" && d != "cw") throw bad();
  *dir = parse_circular_direction(d);
  *suffix = us == std::string::npos ? std::string() : tail.substr(us + 1);
  return true;
}

double mod360(double deg) {
  double a = std::fmod(deg, 360.0);
  return a < 0.0 ? a + 360.0 : a;
}

struct RadialFit {
  Eigen::Vector2d centre;
  double radius = 0.0;
};

Points2 run_points(const CircularRunData& r, double L0) {
  Points2 p(static_cast<Eigen::Index>(r.time.size()), 2);
  for (std::size_t k = 0; k < r.time.size(); ++k) {
    const double L = L0 + r.deviation_mm[k];
    p(static_cast<Eigen::Index>(k), 0) = L * std::cos(r.theta_rad[k]);
    p(static_cast<Eigen::Index>(k), 1) = L * std::sin(r.theta_rad[k]);
  }
  return p;
}

RadialFit lsq_circle(const Points2& p, const std::string& context) {
  CircleFitOptions o;
  o.refine = true;  // ISO 230-4: the least-squares circle (orthogonal distances)
  o.context = context;
  const CircleFit f = hyper_circle_fit(p, o);
  return {f.centre, f.radius};
}

std::vector<double> radial(const Points2& p, const RadialFit& f) {
  std::vector<double> r(static_cast<std::size_t>(p.rows()));
  for (Eigen::Index k = 0; k < p.rows(); ++k)
    r[static_cast<std::size_t>(k)] = (p.row(k).transpose() - f.centre).norm() - f.radius;
  return r;
}

}  // namespace

double CircularRunData::span_deg() const {
  if (theta_rad.empty()) return 0.0;
  return std::abs(theta_rad.back() - theta_rad.front()) * kRad;
}

std::vector<CircularRunData> circular_runs(const BallbarSession& s) {
  std::vector<CircularRunData> out;
  const double L0 = s.ballbar_length;
  if (!(L0 > 0.0)) throw InvalidArgument("circular_runs: ballbar_length must be positive");
  const Eigen::Vector3d tv = tool_vector<double>(s.machine, 0.0);
  for (const std::string& label : s.tests()) {
    CircularRunData r;
    std::string suffix;
    if (!parse_label(label, &r.plane, &r.direction, &suffix)) continue;
    r.label = label;
    r.rows = s.indices_of(label);
    const std::size_t n = r.rows.size();
    if (n < 36)
      throw InvalidArgument("test " + label + ": " + std::to_string(n) +
                            " readings; a circular run needs at least 36");
    const auto ax = plane_axes(r.plane);
    const int nrm = plane_normal(r.plane);
    r.time.resize(n);
    r.theta_rad.resize(n);
    r.deviation_mm.resize(n);
    r.xyz.resize(static_cast<Eigen::Index>(n), 3);
    for (std::size_t k = 0; k < n; ++k) {
      const BallbarSample& b = s.samples[r.rows[k]];
      if (std::abs(b.tilt_deg) > 1e-6 || std::abs(b.rot_deg) > 1e-6)
        throw InvalidArgument("test " + label +
                              ": the rotary axes must be at 0 in a circular run (row at t = " +
                              std::to_string(b.time) + " s)");
      const Eigen::Vector3d rel = b.xyz + tv - s.pivot;
      const double ru = rel[ax[0]], rv = rel[ax[1]];
      if (std::abs(rel[nrm]) > 0.01 * L0 || std::abs(std::hypot(ru, rv) - L0) > 0.01 * L0)
        throw InvalidArgument(
            "test " + label + ": the commanded point at t = " + std::to_string(b.time) +
            " s is not on the circle of radius ballbar_length about the pivot in the " +
            to_string(r.plane) + " plane");
      double th = std::atan2(rv, ru);
      if (k > 0) th = r.theta_rad[k - 1] + std::remainder(th - r.theta_rad[k - 1], 2.0 * kPi);
      r.time[k] = b.time;
      r.theta_rad[k] = th;
      r.deviation_mm[k] = b.length - L0;
      r.xyz.row(static_cast<Eigen::Index>(k)) = b.xyz.transpose();
    }
    const double sense = r.direction == CircularDirection::ccw ? 1.0 : -1.0;
    for (std::size_t k = 1; k < n; ++k)
      if (sense * (r.theta_rad[k] - r.theta_rad[k - 1]) < -1e-9)
        throw InvalidArgument("test " + label + ": the path angle " +
                              (sense > 0 ? "decreases" : "increases") +
                              " at t = " + std::to_string(r.time[k]) + " s, but the label says " +
                              to_string(r.direction));
    // theta = theta0 + omega (t - t0), least squares.
    const double tm = std::accumulate(r.time.begin(), r.time.end(), 0.0) / static_cast<double>(n);
    const double thm =
        std::accumulate(r.theta_rad.begin(), r.theta_rad.end(), 0.0) / static_cast<double>(n);
    double stt = 0.0, sth = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      stt += (r.time[k] - tm) * (r.time[k] - tm);
      sth += (r.time[k] - tm) * (r.theta_rad[k] - thm);
    }
    if (!(stt > 0.0) || !(sense * sth > 0.0))
      throw InvalidArgument("test " + label +
                            ": time or path angle does not advance; a circular run "
                            "needs both to, in the labelled direction");
    r.omega_rad_s = sth / stt;
    r.t0 = tm;
    r.theta0_rad = thm;
    r.feed_mm_per_min = std::abs(r.omega_rad_s) * L0 * 60.0;
    if (suffix.size() > 1 && suffix[0] == 'f') {
      char* end = nullptr;
      const double f = std::strtod(suffix.c_str() + 1, &end);
      if (end && *end == '\0' && f > 0.0 && std::abs(r.feed_mm_per_min / f - 1.0) > 0.02)
        throw InvalidArgument("test " + label + ": the time and angle columns give a feed of " +
                              std::to_string(r.feed_mm_per_min) + " mm/min, the label " + suffix);
    }
    out.push_back(std::move(r));
  }
  if (out.empty())
    throw InvalidArgument(
        "the session has no circular run (tests labelled circular_<XY|YZ|ZX>_<ccw|cw>)");
  return out;
}

CircularAnalysis analyze_circular(const BallbarSession& session) {
  const std::vector<CircularRunData> runs = circular_runs(session);
  const double L0 = session.ballbar_length;
  CircularAnalysis out;
  out.ballbar_length = L0;
  for (const std::string& t : session.tests())
    if (std::none_of(runs.begin(), runs.end(),
                     [&](const CircularRunData& r) { return r.label == t; }))
      out.ignored_tests.push_back(t);
  std::vector<Points2> points;
  for (const CircularRunData& r : runs) {
    if (!(r.span_deg() >= kMinCircularSpanDeg))
      throw InvalidArgument(
          "test " + r.label + ": its data arc spans " + std::to_string(r.span_deg()).substr(0, 6) +
          " deg; an arc shorter than " + std::to_string(static_cast<int>(kMinCircularSpanDeg)) +
          " deg cannot determine the circle's centre (ISO 230-4: a full circle, or a partial "
          "arc of a few tens of degrees at least)");
    points.push_back(run_points(r, L0));
    const RadialFit f = lsq_circle(points.back(), "test " + r.label);
    const std::vector<double> rad = radial(points.back(), f);
    CircularRunResult res;
    res.label = r.label;
    res.plane = r.plane;
    res.direction = r.direction;
    res.feed_mm_per_min = r.feed_mm_per_min;
    res.span_deg = r.span_deg();
    res.n = r.time.size();
    res.centre_um = f.centre * 1e3;
    res.radius_deviation_um = (f.radius - L0) * 1e3;
    res.max_um = *std::max_element(rad.begin(), rad.end()) * 1e3;
    res.min_um = *std::min_element(rad.begin(), rad.end()) * 1e3;
    res.G_um = res.max_um - res.min_um;
    for (std::size_t k = 0; k < rad.size(); ++k) {
      res.angle_deg.push_back(mod360(r.theta_rad[k] * kRad));
      res.radial_um.push_back(rad[k] * 1e3);
    }
    out.runs.push_back(std::move(res));
  }
  // Pairs: each ccw run with the first unused cw run of its plane and feed.
  std::vector<bool> used(runs.size(), false);
  for (std::size_t i = 0; i < runs.size(); ++i) {
    if (runs[i].direction != CircularDirection::ccw) continue;
    for (std::size_t j = 0; j < runs.size(); ++j) {
      if (used[j] || runs[j].direction != CircularDirection::cw || runs[j].plane != runs[i].plane ||
          std::abs(runs[j].feed_mm_per_min / runs[i].feed_mm_per_min - 1.0) > 0.02)
        continue;
      used[j] = true;
      const CircularRunData &a = runs[i], &b = runs[j];
      Points2 both(points[i].rows() + points[j].rows(), 2);
      both << points[i], points[j];
      const RadialFit f = lsq_circle(both, "tests " + a.label + " and " + b.label);
      const std::vector<double> ra = radial(points[i], f), rb = radial(points[j], f);
      CircularPairResult p;
      p.plane = a.plane;
      p.feed_mm_per_min = 0.5 * (a.feed_mm_per_min + b.feed_mm_per_min);
      p.ccw_label = a.label;
      p.cw_label = b.label;
      const auto [mn_a, mx_a] = std::minmax_element(ra.begin(), ra.end());
      const auto [mn_b, mx_b] = std::minmax_element(rb.begin(), rb.end());
      p.G_b_um = (std::max(*mx_a, *mx_b) - std::min(*mn_a, *mn_b)) * 1e3;
      // cw readings in increasing angle, shifted by whole turns onto the ccw run's range.
      const double ma = 0.5 * (a.theta_rad.front() + a.theta_rad.back());
      const double mb = 0.5 * (b.theta_rad.front() + b.theta_rad.back());
      const double shift = 2.0 * kPi * std::round((ma - mb) / (2.0 * kPi));
      std::vector<std::pair<double, double>> cw;
      for (std::size_t k = 0; k < rb.size(); ++k) cw.emplace_back(b.theta_rad[k] + shift, rb[k]);
      std::sort(cw.begin(), cw.end());
      const double lo =
          std::max(std::min(a.theta_rad.front(), a.theta_rad.back()), cw.front().first);
      const double hi =
          std::min(std::max(a.theta_rad.front(), a.theta_rad.back()), cw.back().first);
      p.common_span_deg = std::max(0.0, hi - lo) * kRad;
      for (std::size_t k = 0; k < ra.size(); ++k) {
        const double th = a.theta_rad[k];
        if (th < lo || th > hi) continue;
        auto it = std::lower_bound(cw.begin(), cw.end(), std::make_pair(th, -1e300));
        double rcw;
        if (it == cw.begin()) {
          rcw = it->second;
        } else if (it == cw.end()) {
          rcw = cw.back().second;
        } else {
          const auto& q0 = *(it - 1);
          const auto& q1 = *it;
          const double w = q1.first > q0.first ? (th - q0.first) / (q1.first - q0.first) : 0.0;
          rcw = q0.second + w * (q1.second - q0.second);
        }
        const double h = std::abs(ra[k] - rcw) * 1e3;
        if (h > p.H_um) {
          p.H_um = h;
          p.H_angle_deg = mod360(th * kRad);
        }
      }
      out.pairs.push_back(std::move(p));
      break;
    }
  }
  return out;
}

}  // namespace rotacal

// SPDX-License-Identifier: BSD-3-Clause
// Motion of the rotary axes from a session's time and angle columns (motion.hpp).
#include "rotacal/ballbar/motion.hpp"

#include <algorithm>
#include <cmath>

namespace rotacal {

namespace {

constexpr double kRestRate = 1e-9;  // rad/s

double sign(double rate) { return rate > kRestRate ? 1.0 : rate < -kRestRate ? -1.0 : 0.0; }

// Both angles of a sample through one accessor, so the tilt and the rotary axis share the code.
double& member(RotaryAngles<double>& a, int k) { return k == 0 ? a.tilt : a.rot; }
double member(const RotaryAngles<double>& a, int k) { return k == 0 ? a.tilt : a.rot; }

// When axis k turned before row b, the first of the new direction, a the row before it:
//  - rows a and b follow at the rows' own spacing: where the line through a at its rate meets
//    the line through b at b's, the vertex of a program's piecewise-linear path
//    (ProgramTimeline places the reversal there);
//  - a gap between them (rows not on record, e.g. a transition left out): the axis is taken to
//    have rested at a's angle and to have left it on b's line.
// Kept within the two rows' times.
double turning_time(const std::vector<BallbarSample>& s,
                    const std::vector<RotaryAngles<double>>& angle,
                    const std::vector<RotaryMotion>& m, std::size_t b, int k) {
  const std::size_t a = b - 1;
  const double ra = member(m[a].rate, k), rb = member(m[b].rate, k);
  const double ta = s[a].time, tb = s[b].time;
  double spacing = 0.0;  // the rows' own spacing on either side
  if (a > 0 && s[a - 1].test == s[a].test) spacing = std::max(spacing, ta - s[a - 1].time);
  if (b + 1 < s.size() && s[b + 1].test == s[b].test)
    spacing = std::max(spacing, s[b + 1].time - tb);
  const bool adjacent = spacing > 0.0 && tb - ta <= 1.5 * spacing;
  const double Aa = member(angle[a], k), Ab = member(angle[b], k);
  const double t = adjacent ? (Ab - Aa + ra * ta - rb * tb) / (ra - rb) : tb - (Ab - Aa) / rb;
  return std::isfinite(t) ? std::clamp(t, ta, tb) : tb;
}

}  // namespace

std::vector<RotaryMotion> rotary_motion(const std::vector<BallbarSample>& samples) {
  const std::size_t n = samples.size();
  std::vector<RotaryMotion> out(n);
  std::vector<RotaryAngles<double>> angle(n);
  for (std::size_t i = 0; i < n; ++i) angle[i] = samples[i].angles_rad();

  // Rates within each run of rows of one test.
  for (std::size_t a = 0; a < n;) {
    std::size_t b = a + 1;
    while (b < n && samples[b].test == samples[a].test) ++b;
    for (std::size_t i = a; i < b; ++i) {
      const std::size_t lo = i > a ? i - 1 : i, hi = i + 1 < b ? i + 1 : i;
      const double dt = samples[hi].time - samples[lo].time;
      for (int k = 0; k < 2; ++k)
        member(out[i].rate, k) =
            hi > lo && dt > 0.0 ? (member(angle[hi], k) - member(angle[lo], k)) / dt : 0.0;
    }
    a = b;
  }

  // Directions and reversals, in time order over the whole session.
  for (int k = 0; k < 2; ++k) {
    double last = 0.0;  // direction of the last move on record
    double reversal_time = std::numeric_limits<double>::quiet_NaN();
    for (std::size_t i = 0; i < n; ++i) {
      const double s = sign(member(out[i].rate, k));
      if (s != 0.0) {
        if (last != 0.0 && s != last) reversal_time = turning_time(samples, angle, out, i, k);
        last = s;
      }
      member(out[i].direction, k) = last;
      member(out[i].since_reversal, k) = std::isnan(reversal_time)
                                             ? std::numeric_limits<double>::infinity()
                                             : samples[i].time - reversal_time;
    }
  }
  return out;
}

}  // namespace rotacal

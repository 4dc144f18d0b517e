// Motion of the rotary axes from a session's time and angle columns (motion.hpp).
#include "rotacal/ballbar/motion.hpp"

#include <cmath>

namespace rotacal {

namespace {

constexpr double kRestRate = 1e-9;  // rad/s

double sign(double rate) { return rate > kRestRate ? 1.0 : rate < -kRestRate ? -1.0 : 0.0; }

// Both angles of a sample through one accessor, so the tilt and the rotary axis share the code.
double& member(RotaryAngles<double>& a, int k) { return k == 0 ? a.tilt : a.rot; }

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
        member(out[i].rate, k) = hi > lo && dt > 0.0 ? (member(angle[hi], k) - member(angle[lo], k)) / dt : 0.0;
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
        if (last != 0.0 && s != last) reversal_time = samples[i].time;
        last = s;
      }
      member(out[i].direction, k) = last;
      member(out[i].since_reversal, k) =
          std::isnan(reversal_time) ? std::numeric_limits<double>::infinity() : samples[i].time - reversal_time;
    }
  }
  return out;
}

}  // namespace rotacal

// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The lag state of `thermal_location_R` (../shared/spec/effects.md): a rotary axis' motion
/// heats it, and its location errors and the instrument's table-side point move by a gain
/// times the state y of a first-order lag of the heat input u:
///   tau dy/dt = u - y,  y = 0 at the session's first row,
///   u = |omega_R| / (100 rev/min) from the duty, 0 during the measurement epochs.
/// u is constant between the duty's entries and the epochs' ends, so y is solved exactly on
/// each piece: y(t0 + h) = u + (y(t0) - u) exp(-h / tau). Templated on the scalar: tau (and
/// through it y) is a fit parameter, carried as ln(tau / 300 s) as thermal_warmup's is.

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "rotacal/kinematics/chain_stages.hpp"

namespace rotacal {

/// Piecewise-constant heat input of one axis from the session's first row: u = u[i] on
/// [start[i], start[i + 1]) (the last piece runs on), start[0] the first row's time (s).
struct HeatInput {
  std::vector<double> start;  ///< s, strictly increasing
  std::vector<double> u;      ///< |speed| / (100 rev/min), >= 0
};

/// tau = 300 s e^q: the parameter of a lag's time constant in a fit (q = 0 a sensible start).
template <typename Scalar>
Scalar thermal_tau(const Scalar& q) {
  using std::exp;
  return Scalar(300) * exp(q);
}

/// y(t) of the lag with time constant tau (s) driven by `heat`; 0 at or before start[0].
/// O(pieces before t).
template <typename Scalar>
Scalar lag_state(const HeatInput& heat, double t, const Scalar& tau) {
  using std::exp;
  Scalar y(0);
  const std::size_t n = heat.start.size();
  for (std::size_t i = 0; i < n && heat.start[i] < t; ++i) {
    const double end = i + 1 < n ? std::min(t, heat.start[i + 1]) : t;
    const double h = end - heat.start[i];
    if (h <= 0.0) continue;
    const Scalar u(heat.u[i]);
    y = u + (y - u) * exp(-Scalar(h) / tau);
  }
  return y;
}

/// y at each of `times` (non-decreasing), in one pass over the pieces.
template <typename Scalar>
std::vector<Scalar> lag_states(const HeatInput& heat, const std::vector<double>& times,
                               const Scalar& tau) {
  using std::exp;
  std::vector<Scalar> out;
  out.reserve(times.size());
  Scalar y(0);  // state at heat.start[i] (or the first row)
  std::size_t i = 0;
  const std::size_t n = heat.start.size();
  for (double t : times) {
    while (i + 1 < n && heat.start[i + 1] <= t) {
      const Scalar u(heat.u[i]);
      y = u + (y - u) * exp(-Scalar(heat.start[i + 1] - heat.start[i]) / tau);
      ++i;
    }
    if (n == 0 || t <= heat.start[0]) {
      out.push_back(Scalar(0));
      continue;
    }
    const Scalar u(heat.u[i]);
    out.push_back(u + (y - u) * exp(-Scalar(t - heat.start[i]) / tau));
  }
  return out;
}

/// y at a sequence of non-decreasing times in O(pieces + times) in all, for a fit's residual
/// functor that is called row after row (lag_state from the first piece at every row costs
/// O(pieces) each: 75 pieces x 1,480 touches per Jacobian pass on a 6 h probe test). `at(i, ...)`
/// continues from row i - 1 when the previous call was row i - 1 (same tau), else starts over.
template <typename Scalar>
class LagTracker {
 public:
  Scalar at(long row, const HeatInput& heat, double t, const Scalar& tau) {
    using std::exp;
    if (row != last_ + 1 || t < t_) piece_ = 0, y0_ = Scalar(0), t_ = -1e300;
    last_ = row;
    t_ = t;
    const std::size_t n = heat.start.size();
    if (n == 0 || t <= heat.start[0]) return Scalar(0);
    while (piece_ + 1 < n && heat.start[piece_ + 1] <= t) {
      const Scalar u(heat.u[piece_]);
      y0_ = u + (y0_ - u) * exp(-Scalar(heat.start[piece_ + 1] - heat.start[piece_]) / tau);
      ++piece_;
    }
    const Scalar u(heat.u[piece_]);
    return u + (y0_ - u) * exp(-Scalar(t - heat.start[piece_]) / tau);
  }

 private:
  long last_ = -2;
  double t_ = -1e300;
  std::size_t piece_ = 0;
  Scalar y0_ = Scalar(0);  // y at heat.start[piece_]
};

/// Gains of one lag of `thermal_location_R`: the steady-state change after long turning at
/// 100 rev/min of each location error (machine order, mm or rad) and of the table-side point
/// (table frame, mm).
template <typename Scalar>
struct ThermalGains {
  Eigen::Matrix<Scalar, 8, 1> errors = Eigen::Matrix<Scalar, 8, 1>::Zero();
  Vec3<Scalar> point = Vec3<Scalar>::Zero();
};

/// E0 + K y: the location errors at lag state y.
template <typename Scalar>
LocationErrors<Scalar> drifted_errors(const LocationErrors<Scalar>& cold,
                                      const ThermalGains<Scalar>& k, const Scalar& y) {
  return LocationErrors<Scalar>(cold.v + k.errors * y);
}

/// q0 + K_q y: the table-side point (probe sphere, R-test nest) at lag state y.
template <typename Scalar>
Vec3<Scalar> drifted_point(const Vec3<Scalar>& cold, const ThermalGains<Scalar>& k,
                           const Scalar& y) {
  return cold + k.point * y;
}

}  // namespace rotacal

// SPDX-License-Identifier: BSD-3-Clause
// The columns of the circular-test diagnosis: the readings of every run as rows, the runs'
// baselines (centre offset and radius), and each entry's first-order change of the reading per
// unit parameter.
#include <cmath>

#include "diagnosis_detail.hpp"

namespace rotacal::circular_detail {

namespace {

// Unit vector along the bar, machine axes.
Eigen::Vector3d bar_direction(const Rows& R, std::size_t i) {
  const std::array<int, 2>& ax = R.axes_uv[i];
  Eigen::Vector3d e = Eigen::Vector3d::Zero();
  e[ax[0]] = R.cos_theta[i];
  e[ax[1]] = R.sin_theta[i];
  return e;
}

// Axis a's phase in row i: the commanded axis is centre + R cos(psi); -1 if a does not move.
bool axis_phase(const Rows& R, std::size_t i, int a, double* psi) {
  const std::array<int, 2>& ax = R.axes_uv[i];
  if (ax[0] == a) {
    *psi = R.theta[i];
    return true;
  }
  if (ax[1] == a) {
    *psi = R.theta[i] - kPi / 2.0;
    return true;
  }
  return false;
}

// Direction of travel (+1, -1) of the axis at phase psi in row i.
double travel_sign(const Rows& R, std::size_t i, double psi) {
  // At the turning point itself (a reading exactly at the reversal, e.g. a data arc that
  // starts there) the axis is at rest: no direction, as in the simulator.
  const double sin_psi = std::sin(psi);
  const double v = -sin_psi * R.omega[i];
  return std::abs(sin_psi) < 1e-9 ? 0.0 : (v > 0.0 ? 1.0 : -1.0);
}

// Direction of travel of axis a (+1, -1) and the time since it last reversed (s).
void travel(const Rows& R, std::size_t i, double psi, double* s, double* since) {
  const double w = R.omega[i];
  *s = travel_sign(R, i, psi);
  const double ang = std::fmod(std::fmod(w > 0.0 ? psi : -psi, kPi) + kPi, kPi);
  *since = ang / std::abs(w);
}

}  // namespace

Rows gather(const BallbarSession& s, const std::vector<CircularRunData>& runs) {
  Rows R;
  for (const CircularRunData& r : runs) R.n += r.time.size();
  R.y.resize(static_cast<Eigen::Index>(R.n));
  R.radius = s.ballbar_length;
  R.centre_axes = s.pivot - tool_vector<double>(s.machine, 0.0);
  R.runs = runs.size();
  std::size_t i = 0;
  for (std::size_t k = 0; k < runs.size(); ++k) {
    const CircularRunData& r = runs[k];
    R.planes.insert(r.plane);
    R.directions.insert(r.direction);
    for (int a : plane_axes(r.plane)) R.moving_axes.insert(a);
    R.run_first.push_back(static_cast<Eigen::Index>(i));
    R.run_count.push_back(static_cast<Eigen::Index>(r.time.size()));
    for (std::size_t j = 0; j < r.time.size(); ++j, ++i) {
      R.y[static_cast<Eigen::Index>(i)] = r.deviation_mm[j];
      R.group.push_back(r.label);
      R.time.push_back(r.time[j]);
      R.run.push_back(static_cast<int>(k));
      R.plane.push_back(r.plane);
      R.axes_uv.push_back(plane_axes(r.plane));
      R.theta.push_back(r.theta_rad[j]);
      R.cos_theta.push_back(std::cos(r.theta_rad[j]));
      R.sin_theta.push_back(std::sin(r.theta_rad[j]));
      R.omega.push_back(r.omega_rad_s);
      R.axes.push_back(r.xyz.row(static_cast<Eigen::Index>(j)).transpose());
    }
  }
  return R;
}

Eigen::MatrixXd baseline_columns(const Rows& R) {
  Eigen::MatrixXd B =
      Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(R.n), static_cast<Eigen::Index>(3 * R.runs));
  for (std::size_t i = 0; i < R.n; ++i) {
    const Eigen::Index c = 3 * R.run[i], r = static_cast<Eigen::Index>(i);
    B(r, c) = 1.0;
    B(r, c + 1) = R.cos_theta[i];
    B(r, c + 2) = R.sin_theta[i];
  }
  return B;
}

Eigen::MatrixXd effect_columns(const Rows& R, const CircularEffect& e, const Eigen::Vector3d& pitch,
                               double tau, double delay) {
  const Eigen::Index n = static_cast<Eigen::Index>(R.n);
  const int k = e.kind == CircularEffectKind::cyclic_error ? 2 : 1;
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(n, k);
  const auto pax = plane_axes(e.plane);
  for (std::size_t i = 0; i < R.n; ++i) {
    const Eigen::Index r = static_cast<Eigen::Index>(i);
    const Eigen::Vector3d er = bar_direction(R, i);
    const Eigen::Vector3d& a = R.axes[i];
    switch (e.kind) {
      case CircularEffectKind::squareness: {
        const int u = pax[0], v = pax[1];  // u += s a_v
        J(r, 0) = a[v] * er[u];
        break;
      }
      case CircularEffectKind::scale_mismatch:
        if (R.plane[i] == e.plane)
          J(r, 0) = 0.5 * (a[pax[0]] * er[pax[0]] - a[pax[1]] * er[pax[1]]);
        break;
      case CircularEffectKind::straightness: {
        const double uu = (a[e.axis] - R.centre_axes[e.axis]) / 100.0;
        J(r, 0) = uu * uu * er[e.direction];
        break;
      }
      case CircularEffectKind::backlash: {
        double psi;
        if (!axis_phase(R, i, e.axis, &psi)) break;
        J(r, 0) = -0.5 * travel_sign(R, i, psi - R.omega[i] * delay) * er[e.axis];
        break;
      }
      case CircularEffectKind::reversal_spike: {
        double psi, s, since;
        if (!axis_phase(R, i, e.axis, &psi)) break;
        travel(R, i, psi - R.omega[i] * delay, &s, &since);
        J(r, 0) = -s * std::exp(-since / tau) * er[e.axis];
        break;
      }
      case CircularEffectKind::servo_mismatch:
        if (R.plane[i] == e.plane)
          J(r, 0) = R.radius * R.omega[i] * R.sin_theta[i] * R.cos_theta[i];
        break;
      case CircularEffectKind::cyclic_error: {
        const double q = 2.0 * kPi * a[e.axis] / pitch[e.axis];
        J(r, 0) = std::cos(q) * er[e.axis];
        J(r, 1) = std::sin(q) * er[e.axis];
        break;
      }
    }
  }
  return J;
}

// Why an entry cannot be seen at all by these runs (empty: it can be, as far as its columns go).
std::string not_moved(const Rows& R, const CircularEffect& e) {
  switch (e.kind) {
    case CircularEffectKind::squareness:
    case CircularEffectKind::scale_mismatch:
    case CircularEffectKind::servo_mismatch:
      if (!R.planes.count(e.plane))
        return "no circular run in the " + to_string(e.plane) +
               " plane: only that plane's runs see it";
      return {};
    case CircularEffectKind::straightness:
      for (CircularPlane p : R.planes) {
        const auto ax = plane_axes(p);
        if ((ax[0] == e.axis && ax[1] == e.direction) || (ax[1] == e.axis && ax[0] == e.direction))
          return {};
      }
      return "no circular run in the plane of " + axis_name(e.axis) + " and " +
             axis_name(e.direction) + ": only there does the bar read " + axis_name(e.direction) +
             " while " + axis_name(e.axis) + " moves";
    default:
      if (!R.moving_axes.count(e.axis))
        return "axis " + axis_name(e.axis) + " does not move in any run";
      return {};
  }
}

Eigen::MatrixXd model_columns(const Rows& R, const Eigen::MatrixXd& B,
                              const std::vector<Chosen>& chosen, const Eigen::Vector3d& pitch,
                              std::vector<Eigen::Index>* offsets) {
  Eigen::Index cols = B.cols();
  std::vector<Eigen::MatrixXd> parts;
  for (const Chosen& c : chosen) {
    parts.push_back(effect_columns(R, c.effect, pitch, c.tau, c.delay));
    if (offsets) offsets->push_back(cols);
    cols += parts.back().cols();
  }
  Eigen::MatrixXd M(B.rows(), cols);
  M.leftCols(B.cols()) = B;
  Eigen::Index at = B.cols();
  for (const Eigen::MatrixXd& P : parts) {
    M.middleCols(at, P.cols()) = P;
    at += P.cols();
  }
  return M;
}

}  // namespace rotacal::circular_detail

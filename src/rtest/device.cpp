// SPDX-License-Identifier: BSD-3-Clause
#include "rotacal/rtest/device.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "rotacal/core/angles.hpp"
#include "rotacal/core/error.hpp"

namespace rotacal {

namespace {

void check_dirs(const Eigen::Matrix3d& dirs, const char* what) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(dirs);
  const Eigen::Vector3d s = svd.singularValues();
  if (!(s[2] > 0.0) || s[0] / s[2] > 1e6)
    throw DegenerateGeometry(std::string(what) +
                             ": probe directions are (nearly) linearly dependent");
}
}  // namespace

Eigen::Vector3d sphere_displacement(const Eigen::Matrix3d& dirs, const Eigen::Vector3d& readings) {
  check_dirs(dirs, "sphere_displacement: dirs");
  return dirs.fullPivLu().solve(readings);
}

ProbeCalibration calibrate_probe_directions(const std::vector<ProbeCalibrationSample>& samples) {
  const int n = static_cast<int>(samples.size());
  if (n < 5)
    throw InvalidArgument(
        "calibrate_probe_directions: samples: " + std::to_string(n) +
        " moves cannot determine 4 unknowns per probe with a residual (need >= 5)");
  Eigen::MatrixXd A(n, 4);
  for (int k = 0; k < n; ++k) A.row(k) << samples[k].move.transpose(), 1.0;
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::Vector4d sv = svd.singularValues();
  if (!(sv[3] > 1e-9 * sv[0]))
    throw DegenerateGeometry("calibrate_probe_directions: samples: the moves do not span 3-D");
  const Eigen::Matrix4d AtA_inv =
      svd.matrixV() * sv.cwiseInverse().cwiseAbs2().asDiagonal() * svd.matrixV().transpose();

  ProbeCalibration out;
  out.residuals.assign(samples.size(), Eigen::Vector3d::Zero());
  double ss = 0.0;
  Eigen::Matrix<double, 4, 3> X;
  for (int i = 0; i < 3; ++i) {
    Eigen::VectorXd b(n);
    for (int k = 0; k < n; ++k) b[k] = samples[k].readings[i];
    X.col(i) = svd.solve(b);
    const Eigen::VectorXd r = b - A * X.col(i);
    for (int k = 0; k < n; ++k) out.residuals[static_cast<std::size_t>(k)][i] = r[k];
    ss += r.squaredNorm();
  }
  const double dof = 3.0 * (n - 4);
  const double s2 = ss / dof;
  out.residual_rms_um = std::sqrt(ss / (3.0 * n)) * 1e3;
  out.sigma_um = std::sqrt(s2) * 1e3;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d g = X.col(i).head<3>();
    out.gains[i] = g.norm();
    out.dirs.row(i) = (g / g.norm()).transpose();
    out.zeros[i] = X(3, i);
    // Cov(g) = s2 (A^T A)^-1 (top-left 3x3). Angular std: the part of Cov(g) perpendicular to
    // dir, over |g| (root of the sum over the two perpendicular directions).
    const Eigen::Matrix3d Cg = s2 * AtA_inv.topLeftCorner<3, 3>();
    const Eigen::Vector3d u = g / g.norm();
    const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - u * u.transpose();
    out.direction_std_rad[i] = std::sqrt(std::max(0.0, (P * Cg * P).trace())) / g.norm();
    out.gain_std[i] = std::sqrt(std::max(0.0, double(u.transpose() * Cg * u)));
  }
  return out;
}

std::vector<ProbeCalibrationSample> simulate_probe_calibration(
    const Eigen::Matrix3d& dirs, const Eigen::Vector3d& zeros,
    const std::vector<Eigen::Vector3d>& moves, double noise_um, unsigned seed) {
  if (noise_um < 0) throw InvalidArgument("simulate_probe_calibration: noise_um must be >= 0");
  std::mt19937 rng(seed);
  std::normal_distribution<double> N(0.0, noise_um * 1e-3);
  std::vector<ProbeCalibrationSample> out;
  for (const Eigen::Vector3d& m : moves) {
    ProbeCalibrationSample s;
    s.move = m;
    s.readings = dirs * m + zeros;
    for (int i = 0; i < 3; ++i) s.readings[i] += N(rng);
    out.push_back(s);
  }
  return out;
}

std::vector<Eigen::Vector3d> default_calibration_moves(double step_mm) {
  if (!(step_mm > 0)) throw InvalidArgument("default_calibration_moves: step_mm must be > 0");
  std::vector<Eigen::Vector3d> m;
  for (int k = 0; k < 3; ++k)
    for (double s : {-1.0, 1.0}) m.push_back(s * step_mm * Eigen::Vector3d::Unit(k));
  for (double a : {-1.0, 1.0})
    for (double b : {-1.0, 1.0}) {
      m.push_back(step_mm / std::sqrt(3.0) * Eigen::Vector3d(1.0, a, b));
      m.push_back(-step_mm / std::sqrt(3.0) * Eigen::Vector3d(1.0, a, b));
    }
  return m;
}

SphereOffsetCalibration calibrate_sphere_offset(const Eigen::Matrix3d& dirs,
                                                const std::vector<SpindleIndexSample>& samples) {
  const int n = static_cast<int>(samples.size());
  if (n < 3)
    throw InvalidArgument("calibrate_sphere_offset: samples: need >= 3 spindle angles, got " +
                          std::to_string(n));
  check_dirs(dirs, "calibrate_sphere_offset: dirs");
  // Unknowns (cx, cy, cz, ox, oy): d_x = cx + cos t ox - sin t oy; d_y = cy + sin t ox + cos t oy;
  // d_z = cz.
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(3 * n, 5);
  Eigen::VectorXd b(3 * n);
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector3d d = dirs.fullPivLu().solve(samples[k].readings);
    const double c = std::cos(samples[k].angle), s = std::sin(samples[k].angle);
    A.row(3 * k) << 1, 0, 0, c, -s;
    A.row(3 * k + 1) << 0, 1, 0, s, c;
    A.row(3 * k + 2) << 0, 0, 1, 0, 0;
    b.segment<3>(3 * k) = d;
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd sv = svd.singularValues();
  if (!(sv[4] > 1e-6 * sv[0]))
    throw DegenerateGeometry(
        "calibrate_sphere_offset: samples: spindle angles too close to separate offset and centre");
  const Eigen::VectorXd x = svd.solve(b);
  const Eigen::VectorXd r = b - A * x;
  // z rows carry only cz: they add nothing to the xy residual. dof = 2n - 4 for the xy rows.
  double ss_xy = 0.0;
  for (int k = 0; k < n; ++k) ss_xy += r.segment<2>(3 * k).squaredNorm();
  const double s2 = n > 2 ? ss_xy / (2.0 * n - 4.0) : 0.0;
  const Eigen::MatrixXd cov =
      s2 * svd.matrixV() * sv.cwiseInverse().cwiseAbs2().asDiagonal() * svd.matrixV().transpose();
  SphereOffsetCalibration out;
  out.centre = x.head<3>();
  out.offset = x.tail<2>();
  out.offset_std = Eigen::Vector2d(std::sqrt(cov(3, 3)), std::sqrt(cov(4, 4)));
  out.residual_rms_um = std::sqrt(ss_xy / (2.0 * n)) * 1e3;
  return out;
}

std::vector<SpindleIndexSample> simulate_spindle_indexing(const Eigen::Matrix3d& dirs,
                                                          const Eigen::Vector3d& zeros,
                                                          const Eigen::Vector2d& offset,
                                                          const Eigen::Vector3d& centre,
                                                          const std::vector<double>& angles,
                                                          double noise_um, unsigned seed) {
  if (noise_um < 0) throw InvalidArgument("simulate_spindle_indexing: noise_um must be >= 0");
  std::mt19937 rng(seed);
  std::normal_distribution<double> N(0.0, noise_um * 1e-3);
  std::vector<SpindleIndexSample> out;
  for (double a : angles) {
    const Eigen::Vector3d o(offset.x(), offset.y(), 0.0);
    const Eigen::Vector3d p = centre + rotation_about_axis<double>(Eigen::Vector3d::UnitZ(), a) * o;
    SpindleIndexSample s;
    s.angle = a;
    s.readings = dirs * p + zeros;
    for (int i = 0; i < 3; ++i) s.readings[i] += N(rng);
    out.push_back(s);
  }
  return out;
}

RtestSession compensate_sphere_offset(const RtestSession& session, const Eigen::Vector2d& offset) {
  RtestSession out = session;
  const Eigen::Vector3d o(offset.x(), offset.y(), 0.0);
  const MachineType m = session.machine;
  for (RtestSample& s : out.samples) {
    if (!s.d) throw InvalidArgument("compensate_sphere_offset: a sample has no dx,dy,dz");
    // The offset turns with the spindle (the head's nominal rotation; none without head axes)
    // and the table frame sees it through the table's nominal rotation.
    const RotaryAngles<double> a = s.angles_rad();
    const Eigen::Matrix3d R = table_pose<double>(m, LocationErrors<double>(), a).R;
    const Eigen::Matrix3d H = head_pose<double>(m, LocationErrors<double>(), a).R;
    *s.d -= R.transpose() * (H * o);
  }
  return out;
}

RtestSession displacements_from_raw(const RtestSession& session, const Eigen::Matrix3d& dirs) {
  check_dirs(dirs, "displacements_from_raw: dirs");
  RtestSession out = session;
  for (std::size_t i = 0; i < out.samples.size(); ++i) {
    RtestSample& s = out.samples[i];
    if (s.d) continue;
    if (!s.raw)
      throw InvalidArgument("displacements_from_raw: pose " + std::to_string(i) + " (setup " +
                            s.setup + ", time " + std::to_string(s.time) +
                            " s) has neither dx,dy,dz nor d1,d2,d3");
    s.d = dirs.fullPivLu().solve(*s.raw);
  }
  return out;
}

RtestSession displacements_from_raw(const RtestSession& session) {
  bool need = false;
  for (const RtestSample& s : session.samples) need = need || (!s.d && s.raw);
  if (!need) return displacements_from_raw(session, Eigen::Matrix3d::Identity());
  Eigen::Matrix3d dirs;
  for (int k = 1; k <= 3; ++k) {
    const auto it = session.probe_dirs.find(k);
    if (it == session.probe_dirs.end())
      throw InvalidArgument(
          "displacements_from_raw: the session has raw readings d1,d2,d3 but no probe." +
          std::to_string(k) + ".dir (the file needs a '# probe." + std::to_string(k) +
          ".dir: x, y, z' metadata line, or convert with calibrated directions)");
    dirs.row(k - 1) = it->second.transpose();
  }
  return displacements_from_raw(session, dirs);
}

}  // namespace rotacal

// SPDX-License-Identifier: BSD-3-Clause
// Oyama & Ibaraki's two-step R-test identification (Eqs. 10-22).
#include "rotacal/rtest/identify_paper.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <map>

#include "rotacal/core/angles.hpp"
#include "rotacal/core/error.hpp"

namespace rotacal {

namespace {
using Mat36 = Eigen::Matrix<double, 3, 6>;

// Sensitivity of the small-angle reading (Eq. 8 with the sign of Sec. 5.1) to w_BY / w_CB.
Mat36 S_of(bool by, double B, double C, const Eigen::Vector3d& q) {
  Mat36 S;
  for (int k = 0; k < 6; ++k) {
    AxisErrors<double> w = AxisErrors<double>::Zero(), z = AxisErrors<double>::Zero();
    w[k] = 1.0;
    S.col(k) = by ? oyama_small_angle_displacement<double>(w, z, B, C, q)
                  : oyama_small_angle_displacement<double>(z, w, B, C, q);
  }
  return S;
}

int index_of(const std::vector<double>& v, double x) {
  for (std::size_t i = 0; i < v.size(); ++i)
    if (std::abs(v[i] - x) < 1e-9) return static_cast<int>(i);
  return -1;
}

// Linear least squares with covariance; components along null directions are set to zero
// (minimum-norm) and get std 0. Returns rank.
int solve_paper_ls(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, Eigen::VectorXd& x,
                   Eigen::VectorXd& std, double& ss) {
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd s = svd.singularValues();
  const double tol = 1e-8 * s[0];
  int rank = 0;
  for (int k = 0; k < s.size(); ++k) rank += s[k] > tol;
  Eigen::VectorXd sinv = Eigen::VectorXd::Zero(s.size());
  for (int k = 0; k < rank; ++k) sinv[k] = 1.0 / s[k];
  x = svd.matrixV() * sinv.asDiagonal() * svd.matrixU().transpose() * b;
  ss = (b - A * x).squaredNorm();
  const double dof = static_cast<double>(A.rows() - rank);
  const double s2 = dof > 0 ? ss / dof : 0.0;
  const Eigen::MatrixXd cov =
      s2 * svd.matrixV() * sinv.cwiseAbs2().asDiagonal() * svd.matrixV().transpose();
  std = cov.diagonal().cwiseMax(0.0).cwiseSqrt();
  return rank;
}
}  // namespace

AxisErrors<double> RtestPaperIdentification::w_BY_at(double B) const {
  const double b = B / kDeg;
  if (b <= b_deg.front()) return w_BY.front();
  if (b >= b_deg.back()) return w_BY.back();
  std::size_t i = 0;
  while (b_deg[i + 1] < b) ++i;
  const double f = (b - b_deg[i]) / (b_deg[i + 1] - b_deg[i]);
  return (1 - f) * w_BY[i] + f * w_BY[i + 1];
}

AxisErrors<double> RtestPaperIdentification::w_CB_at(double B, double C) const {
  auto along_c = [&](std::size_t i) {
    double c = std::fmod(C / kDeg, 360.0);
    if (c < 0) c += 360.0;
    const std::size_t n = c_deg.size();
    std::size_t j = n - 1;  // segment [c_deg[j], c_deg[j+1 mod n] (+360)]
    for (std::size_t k = 0; k + 1 < n; ++k)
      if (c >= c_deg[k] && c < c_deg[k + 1]) j = k;
    double c0 = c_deg[j], c1 = j + 1 < n ? c_deg[j + 1] : c_deg[0] + 360.0;
    if (c < c0) c += 360.0;
    const double f = (c - c0) / (c1 - c0);
    return AxisErrors<double>((1 - f) * w_CB[i][j] + f * w_CB[i][(j + 1) % n]);
  };
  const double b = B / kDeg;
  if (b <= b_deg.front()) return along_c(0);
  if (b >= b_deg.back()) return along_c(b_deg.size() - 1);
  std::size_t i = 0;
  while (b_deg[i + 1] < b) ++i;
  const double f = (b - b_deg[i]) / (b_deg[i + 1] - b_deg[i]);
  return (1 - f) * along_c(i) + f * along_c(i + 1);
}

Eigen::Vector3d RtestPaperIdentification::predict_reading(const Eigen::Vector3d& q, double B,
                                                          double C) const {
  return oyama_displacement<double>(w_BY_at(B), w_CB_at(B, C), B, C, q) -
         oyama_displacement<double>(w_BY_at(0.0), w_CB_at(0.0, 0.0), 0.0, 0.0, q);
}

RtestPaperIdentification identify_paper(const RtestSession& session) {
  if (session.machine != MachineType::BC_trt)
    throw InvalidArgument(
        "identify_paper: session.machine: Oyama's two-step method is written for a "
        "BC-trt table, this session is a " +
        to_string(session.machine) +
        "; use the joint fit (identify_joint, `rotacal identify --method joint`), which "
        "works on any machine");
  const std::vector<std::string> setups = session.setups();
  if (setups.size() < 2)
    throw InvalidArgument("identify_paper: session: the C-axis step needs >= 2 nests, got " +
                          std::to_string(setups.size()));
  RtestPaperIdentification out;
  for (const RtestSample& s : session.samples) {
    if (!s.d) throw InvalidArgument("identify_paper: session: a sample has no dx,dy,dz");
    if (index_of(out.b_deg, s.tilt_deg) < 0) out.b_deg.push_back(s.tilt_deg);
    const double c = std::fmod(std::fmod(s.rot_deg, 360.0) + 360.0, 360.0);
    if (index_of(out.c_deg, c) < 0) out.c_deg.push_back(c);
  }
  std::sort(out.b_deg.begin(), out.b_deg.end());
  std::sort(out.c_deg.begin(), out.c_deg.end());
  const std::size_t nB = out.b_deg.size(), nC = out.c_deg.size(), nS = setups.size();
  const int i0 = index_of(out.b_deg, 0.0), j0 = index_of(out.c_deg, 0.0);
  if (i0 < 0 || j0 < 0)
    throw InvalidArgument("identify_paper: session: no reference pose B = C = 0 (Sec. 4.1)");
  if (nC < 3) throw InvalidArgument("identify_paper: session: need >= 3 C positions per B");

  // d[s][i][j] relative to the reference pose of its set-up (removes the probe zero).
  std::vector<std::vector<std::vector<Eigen::Vector3d>>> d(
      nS, std::vector<std::vector<Eigen::Vector3d>>(nB, std::vector<Eigen::Vector3d>(nC)));
  std::vector<std::vector<std::vector<int>>> seen(
      nS, std::vector<std::vector<int>>(nB, std::vector<int>(nC, 0)));
  std::vector<Eigen::Vector3d> q(nS);
  for (std::size_t k = 0; k < nS; ++k) {
    const auto it = session.nests.find(setups[k]);
    if (it == session.nests.end())
      throw InvalidArgument("identify_paper: session.nests: no nest." + setups[k]);
    q[k] = it->second;
  }
  for (const RtestSample& s : session.samples) {
    const std::size_t k =
        static_cast<std::size_t>(std::find(setups.begin(), setups.end(), s.setup) - setups.begin());
    const int i = index_of(out.b_deg, s.tilt_deg);
    const int j = index_of(out.c_deg, std::fmod(std::fmod(s.rot_deg, 360.0) + 360.0, 360.0));
    d[k][i][j] = *s.d;
    ++seen[k][i][j];
  }
  for (std::size_t k = 0; k < nS; ++k)
    for (std::size_t i = 0; i < nB; ++i)
      for (std::size_t j = 0; j < nC; ++j)
        if (seen[k][i][j] != 1)
          throw InvalidArgument(
              "identify_paper: session: set-up " + setups[k] + " has " +
              std::to_string(seen[k][i][j]) + " samples at B = " + std::to_string(out.b_deg[i]) +
              ", C = " + std::to_string(out.c_deg[j]) + " (need exactly one per grid pose)");
  for (std::size_t k = 0; k < nS; ++k) {
    const Eigen::Vector3d ref = d[k][i0][j0];
    for (auto& row : d[k])
      for (auto& v : row) v -= ref;
  }
  out.n_samples = session.samples.size();

  // Step 1 (Eqs. 13-15): B = 0 first (its constant terms cancel against the reference, so
  // dz_BY(0) and gamma_BY(0) are invisible and set to zero), then every other B_i with w(B1)
  // substituted.
  out.w_BY.assign(nB, AxisErrors<double>::Zero());
  out.w_BY_std.assign(nB, AxisErrors<double>::Zero());
  double ss_b = 0.0;
  auto fit_b = [&](std::size_t i) {
    const double B = out.b_deg[i] * kDeg;
    Eigen::MatrixXd A(3 * nC * nS, 6);
    Eigen::VectorXd b(3 * nC * nS);
    int r = 0;
    for (std::size_t k = 0; k < nS; ++k) {
      const Mat36 S0 = S_of(true, 0.0, 0.0, q[k]);
      for (std::size_t j = 0; j < nC; ++j, r += 3) {
        const Mat36 S = S_of(true, B, out.c_deg[j] * kDeg, q[k]);
        if (static_cast<int>(i) == i0) {
          A.middleRows<3>(r) = S - S0;
          b.segment<3>(r) = d[k][i][j];
        } else {
          A.middleRows<3>(r) = S;
          b.segment<3>(r) = d[k][i][j] + S0 * out.w_BY[static_cast<std::size_t>(i0)];
        }
      }
    }
    Eigen::VectorXd x, sd;
    double ss = 0.0;
    const int rank = solve_paper_ls(A, b, x, sd, ss);
    ss_b += ss;
    out.w_BY[i] = x;
    out.w_BY_std[i] = sd;
    if (rank < 6)
      out.unobservable.push_back("B = " + std::to_string(out.b_deg[i]) +
                                 " deg: " + std::to_string(6 - rank) +
                                 " combination(s) of w_BY are invisible relative to the reference "
                                 "pose and set to zero");
  };
  fit_b(static_cast<std::size_t>(i0));
  for (std::size_t i = 0; i < nB; ++i)
    if (static_cast<int>(i) != i0) fit_b(i);
  out.b_step_rms_um = std::sqrt(ss_b / (3.0 * nS * nB * nC)) * 1e3;

  // Step 2 (Eqs. 16-22): residual after the B errors, in the B-axis frame (rotate by Rz(C)):
  // r_k = -(eps x P_k + delta), eps = (alpha, beta, 0). Unknowns (dx, dy, dz, alpha, beta).
  out.w_CB.assign(nB, std::vector<AxisErrors<double>>(nC, AxisErrors<double>::Zero()));
  out.w_CB_std = out.w_CB;
  double ss_c = 0.0;
  for (std::size_t i = 0; i < nB; ++i)
    for (std::size_t j = 0; j < nC; ++j) {
      const double B = out.b_deg[i] * kDeg, C = out.c_deg[j] * kDeg;
      const Eigen::Matrix3d Rz = rotation_about_axis<double>(Eigen::Vector3d::UnitZ(), C);
      Eigen::MatrixXd A(3 * nS, 5);
      Eigen::VectorXd b(3 * nS);
      for (std::size_t k = 0; k < nS; ++k) {
        const Eigen::Vector3d pred =
            S_of(true, B, C, q[k]) * out.w_BY[i] -
            S_of(true, 0.0, 0.0, q[k]) * out.w_BY[static_cast<std::size_t>(i0)];
        const Eigen::Vector3d rB = Rz * (d[k][i][j] - pred);
        const Eigen::Vector3d P = Rz * q[k];
        A.middleRows<3>(3 * k) << -1, 0, 0, 0, -P.z(),  //
            0, -1, 0, P.z(), 0,                         //
            0, 0, -1, -P.y(), P.x();
        b.segment<3>(3 * k) = rB;
      }
      Eigen::VectorXd x, sd;
      double ss = 0.0;
      solve_paper_ls(A, b, x, sd, ss);
      ss_c += ss;
      out.w_CB[i][j] << x[0], x[1], x[2], x[3], x[4], 0.0;
      out.w_CB_std[i][j] << sd[0], sd[1], sd[2], sd[3], sd[4], 0.0;
    }
  out.residual_rms_um = std::sqrt(ss_c / (3.0 * nS * nB * nC)) * 1e3;
  out.unobservable.push_back(
      "gamma_CB (angular positioning of C) is not identified: assumed zero (Sec. 4.2)");
  out.notes = {
      "reference pose B1 = C1 = 0: every reading is taken relative to it (removes the probe zero); "
      "all errors are relative to that pose",
      "step 1 assumes the C-axis errors are zero: C-axis location errors (centre offset, tilt) "
      "appear in w_BY (Sec. 5.3)",
      "gamma_CB(B_i, C_j) = 0 assumed (Sec. 4.2)",
      "small-angle (first-order) model of Eqs. 8-9 in both steps",
      "maps are given only at the measured (B_i, C_j); predictions in between interpolate "
      "linearly"};
  return out;
}

}  // namespace rotacal

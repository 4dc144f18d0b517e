// SPDX-License-Identifier: BSD-3-Clause
// The ballbar reading's chain rule (length_chain.hpp).
#include "length_chain.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "../kinematics/stage_instances.hpp"
#include "length_model.hpp"

namespace rotacal {
ROTACAL_STAGE_SCALARS(extern)
}  // namespace rotacal

namespace rotacal::length_chain {

namespace {

// The chain rule's forward pass: the pivot carried through the table's stages in
// walk_table_stages' own order (the one definition of it), keeping what the backward pass needs.
struct ForwardPass {
  Eigen::Vector3d p;             // the point after the stages so far
  Eigen::Vector3d pE[2], pK[2];  // the points E's and K's left rotations act on
  Eigen::Vector3d arm[2];        // the point less the axis line's point, after the turn
  std::optional<Eigen::Matrix3d> RE[2], RK[2];  // E's and K's rotations (none: an identity stage)
  LineRotationDerivatives<double> D[2];         // each axis rotation with its derivatives

  explicit ForwardPass(const Eigen::Vector3d& pivot) : p(pivot) {
    for (int k = 0; k < 2; ++k) pE[k] = pK[k] = arm[k] = Eigen::Vector3d::Zero();
  }
  void rigid(const Pose<double>& P, int k, RigidStage stage) {
    const Eigen::Vector3d Rp = P.R * p;
    if (stage == RigidStage::error_motion)
      RE[k] = P.R;
    else
      RK[k] = P.R;
    (stage == RigidStage::error_motion ? pE[k] : pK[k]) = Rp;
    p = Rp + P.t;
  }
  void about_line(const AxisLine<double>& line, double angle, int k) {
    if (!RE[k]) pE[k] = p;
    const double inv_norm = 1.0 / line.direction.norm();
    D[k] = rotate_point_about_unit_line_derivatives<double>(
        line.point, line.direction * inv_norm, inv_norm, std::cos(angle), std::sin(angle), p);
    p = D[k].f;
    arm[k] = p - line.point;
    pK[k] = p;  // K's rotation, if any, replaces it
  }
  void translate(const Eigen::Vector3d& d) { p += d; }
};

}  // namespace

void sensitivities(MachineType m, const LocationErrors<double>& e, const Eigen::Vector3d& pivot,
                   const EffectModel& fx, const double* q, const Sample& smp, Places& s,
                   Eigen::Matrix<double, 1, 11>* base) {
  using Row = Eigen::RowVector3d;
  const int nt = static_cast<int>(m.description().table_axes.size());
  ForwardPass fw(pivot);
  walk_table_stages<double>(m, e, fx, q, smp.angles, smp.time, smp.motion, fw);
  const Eigen::Vector3d& p = fw.p;
  const Eigen::Vector3d tool =
      tool_position<double>(m, e, fx, q, smp.xyz, smp.angles, smp.time, 0.0, smp.motion);
  const Eigen::Vector3d u = (tool - p).normalized();
  // Backward from the reading: g = dL / d(the point after the stage at hand).
  s.setZero();
  s.segment<3>(kTool) = u;
  s[kReading] = 1.0;
  Eigen::Vector3d g = -u;
  s.segment<3>(kD) = g;
  for (int k = 0; k < nt; ++k) {
    s.segment<3>(kKw + 3 * k) = fw.pK[k].cross(g);  // d(w x p) = p x g . dw
    if (fw.RK[k]) g = fw.RK[k]->transpose() * g;
    const Row w = g.transpose();
    s[kAngle + k] = g.dot(fw.D[k].u.cross(fw.arm[k]));  // d f / d angle = u x (f - point)
    const Row wq = fw.D[k].times_q(w);
    if (base) {
      const RotaryAxis& a = m.description().axis(k);
      const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - fw.D[k].u * fw.D[k].u.transpose();
      base->segment<2>(4 * k) = fw.D[k].times_point(w, wq) * a.position_basis;
      base->segment<2>(4 * k + 2) =
          fw.D[k].times_unit_direction(w) * (P * fw.D[k].inv_norm * a.direction_basis);
    }
    g = wq.transpose();
    s.segment<3>(kEt + 3 * k) = g;
    s.segment<3>(kEw + 3 * k) = fw.pE[k].cross(g);
    if (fw.RE[k]) g = fw.RE[k]->transpose() * g;
  }
  if (base) base->segment<3>(8) = g.transpose();
}

template <int N>
void place_derivatives(MachineType m, const EffectModel& fx, const ceres::Jet<double, N>* q,
                       const Sample& smp, Eigen::Matrix<double, kPlaces, N>& d) {
  using Jet = ceres::Jet<double, N>;
  const int nt = static_cast<int>(m.description().table_axes.size());
  const detail::AxisStages<Jet> st =
      detail::axis_stages<Jet>(m, fx, q, smp.angles, smp.time, smp.motion);
  d.setZero();
  // w of a left rotation: dR R^T = [dw]x, w = (M(2,1), M(0,2), M(1,0)) of M = dR R^T.
  // A candidate at 0 has R = I, so M = dR (exactly what the product gives): no product then.
  const auto rotation = [&](int place, const Mat3<Jet>& R) {
    Eigen::Matrix3d value;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) value(i, j) = R(i, j).a;
    if (value == Eigen::Matrix3d::Identity()) {
      d.row(place) = R(2, 1).v.transpose();
      d.row(place + 1) = R(0, 2).v.transpose();
      d.row(place + 2) = R(1, 0).v.transpose();
      return;
    }
    for (int c = 0; c < N; ++c) {
      Eigen::Matrix3d dR;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) dR(i, j) = R(i, j).v[c];
      const Eigen::Matrix3d M = dR * value.transpose();
      d(place, c) = M(2, 1), d(place + 1, c) = M(0, 2), d(place + 2, c) = M(1, 0);
    }
  };
  for (int k = 0; k < nt; ++k) {
    d.row(kAngle + k) = st.angle[k].v.transpose();
    if (st.E[k]) {
      for (int a = 0; a < 3; ++a) d.row(kEt + 3 * k + a) = st.E[k]->t[a].v.transpose();
      rotation(kEw + 3 * k, st.E[k]->R);
    }
    if (st.K[k]) rotation(kKw + 3 * k, st.K[k]->R);
  }
  if (st.D[0])
    for (int a = 0; a < 3; ++a) d.row(kD + a) = (*st.D[0])[a].v.transpose();
  const Vec3<Jet> tool = linear_axes_position<Jet>(fx, q, smp.xyz) + tool_offset<Jet>(fx, q);
  for (int a = 0; a < 3; ++a) d.row(kTool + a) = tool[a].v.transpose();
  d.row(kReading) = ballbar_reading_error<Jet>(fx, q, smp.time).v.transpose();
}

template void place_derivatives<1>(MachineType, const EffectModel&, const ceres::Jet<double, 1>*,
                                   const Sample&, Eigen::Matrix<double, kPlaces, 1>&);
template void place_derivatives<4>(MachineType, const EffectModel&, const Jet4*, const Sample&,
                                   Eigen::Matrix<double, kPlaces, 4>&);

}  // namespace rotacal::length_chain

namespace rotacal {

// The fit's residuals (the one residual, on doubles) and Jacobian by the chain rule: the
// location errors and pivot from the backward pass, the effects' parameters four at a time
// by Jets of their stages alone.
void BallbarLengthModel::evaluate_chain(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> r,
                                        Eigen::MatrixXd& J) const {
  using length_chain::Jet4;
  const MachineType m = d_.machine;
  const LocationErrors<double> e(L_.errors.of<8>(x));
  const Eigen::Vector3d pivot = L_.pivots.of<3>(x);
  const double* q = L_.effects.ptr(x.data());
  const int np = static_cast<int>(L_.effects.size);
  std::vector<Jet4> qj(static_cast<std::size_t>(np));
  const RotaryMotion still{};
  length_chain::Places s;
  Eigen::Matrix<double, 1, 11> base;
  Eigen::Matrix<double, length_chain::kPlaces, 4> d;
  for (Eigen::Index i = 0; i < d_.size(); ++i) {
    const std::size_t k = static_cast<std::size_t>(i);
    const Eigen::Vector3d xyz = d_.xyz.col(i);
    const length_chain::Sample smp{xyz, d_.angles[k], d_.time[i],
                                   d_.motion.empty() ? still : d_.motion[k]};
    r[i] = ballbar_residual<double>(L_, d_, fx_, x.data(), i);
    length_chain::sensitivities(m, e, pivot, fx_, q, smp, s, &base);
    J.block<1, 8>(i, L_.errors.offset) = base.head<8>();
    J.block<1, 3>(i, L_.pivots.offset) = base.tail<3>();
    for (int c0 = 0; c0 < np; c0 += 4) {
      for (int j = 0; j < np; ++j) qj[static_cast<std::size_t>(j)] = Jet4(q[j]);
      const int width = std::min(4, np - c0);
      for (int c = 0; c < width; ++c) qj[static_cast<std::size_t>(c0 + c)] = Jet4(q[c0 + c], c);
      length_chain::place_derivatives(m, fx_, qj.data(), smp, d);
      const Eigen::RowVector4d row = s.transpose() * d;
      for (int c = 0; c < width; ++c) J(i, L_.effects.offset + c0 + c) = row[c];
    }
  }
}

}  // namespace rotacal

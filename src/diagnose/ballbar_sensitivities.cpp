// The ballbar candidates' Jacobians by the chain rule (ballbar_sensitivities.hpp).
#include "ballbar_sensitivities.hpp"

#include <ceres/jet.h>

#include <cmath>

#include "rotacal/ballbar/problem.hpp"

namespace rotacal::diagnosis_detail {

namespace {

// The small rotation w of a rotation matrix that is the identity at the effect's zero:
// d R = [d w]x, so d w = (dR(2,1), dR(0,2), dR(1,0)) (the Jets' derivative parts).
template <typename Jet>
Eigen::Matrix<double, 3, Jet::DIMENSION> small_rotation(const Mat3<Jet>& R) {
  Eigen::Matrix<double, 3, Jet::DIMENSION> w;
  w.row(0) = R(2, 1).v.transpose();
  w.row(1) = R(0, 2).v.transpose();
  w.row(2) = R(1, 0).v.transpose();
  return w;
}

}  // namespace

BallbarSensitivities::BallbarSensitivities(MachineType m, const std::vector<BallbarSample>& samples,
                                           const std::vector<RotaryMotion>& motion, const ModelFit& at)
    : m_(m), samples_(samples), motion_(motion), s_(kPlaces, static_cast<Eigen::Index>(samples.size())) {
  ROTACAL_ASSERT(supports(m) && motion.size() == samples.size());
  reference_.linear_reference = at.effects.linear_reference;
  const BallbarLayout L = ballbar_layout(m, at.effects);
  Eigen::VectorXd x(static_cast<Eigen::Index>(at.parameters.size()));
  for (std::size_t i = 0; i < at.parameters.size(); ++i) x[static_cast<Eigen::Index>(i)] = at.parameters[i].value;
  const LocationErrors<double> e(L.errors.of<8>(x));
  const Eigen::Vector3d pivot = L.pivots.of<3>(x);
  const double* p = L.effects.ptr(x.data());
  const int nt = static_cast<int>(m.description().table_axes.size());
  angles_.reserve(samples.size());
  for (std::size_t r = 0; r < samples.size(); ++r) {
    const BallbarSample& smp = samples[r];
    angles_.push_back(smp.angles_rad());
    const detail::AxisStages<double> st =
        detail::axis_stages<double>(m, at.effects, p, angles_.back(), smp.time, motion[r]);
    // Forward, as walk_table_stages composes (innermost axis first): the points a left
    // rotation of E or K acts on, and each rotation's axis and output about its line.
    Eigen::Vector3d pE[2], pK[2], n[2], arm[2];
    Eigen::Vector3d q = pivot;
    for (int k = nt - 1; k >= 0; --k) {
      pE[k] = st.E[k] ? Eigen::Vector3d(st.E[k]->R * q) : q;
      q = st.E[k] ? Eigen::Vector3d(pE[k] + st.E[k]->t) : q;
      const AxisLine<double> line = axis_line(m, k, e);
      n[k] = line.direction.normalized();
      q = rotate_point_about_unit_line<double>(line.point, n[k], std::cos(st.angle[k]), std::sin(st.angle[k]), q);
      arm[k] = q - line.point;
      pK[k] = st.K[k] ? Eigen::Vector3d(st.K[k]->R * q) : q;
      q = st.K[k] ? Eigen::Vector3d(pK[k] + st.K[k]->t) : q;
    }
    if (st.D[0]) q += *st.D[0];
    const Eigen::Vector3d tool =
        tool_position<double>(m, e, at.effects, p, smp.xyz, angles_.back(), smp.time, 0.0, motion[r]);
    const Eigen::Vector3d u = (tool - q).normalized();
    // Backward from the reading: g = dL / d(the point after the stage at hand).
    auto s = s_.col(static_cast<Eigen::Index>(r));
    s.setZero();
    s.segment<3>(kTool) = u;
    Eigen::Vector3d g = -u;
    s.segment<3>(kD) = g;
    for (int k = 0; k < nt; ++k) {
      s.segment<3>(kKw + 3 * k) = pK[k].cross(g);  // d(w x p) = p x g . dw
      if (st.K[k]) g = st.K[k]->R.transpose() * g;
      s[kAngle + k] = g.dot(n[k].cross(arm[k]));
      g = rotation_about_axis<double>(n[k], st.angle[k]).transpose() * g;
      s.segment<3>(kEt + 3 * k) = g;
      s.segment<3>(kEw + 3 * k) = pE[k].cross(g);
      if (st.E[k]) g = st.E[k]->R.transpose() * g;
    }
  }
}

Eigen::MatrixXd BallbarSensitivities::columns(const Effect& effect, const std::vector<int>& seed) const {
  // One Jet width for every candidate (1 to 4 parameters): its own stages are cheap, and one
  // instantiation of the stages keeps the compile time down.
  using Jet = ceres::Jet<double, 4>;
  ROTACAL_ASSERT(seed.size() <= 4 && effect.num_params() <= 4);
  EffectModel fx = reference_;
  fx.effects = {effect};
  Jet q[4] = {Jet(0.0), Jet(0.0), Jet(0.0), Jet(0.0)};
  for (std::size_t k = 0; k < seed.size(); ++k) q[seed[k]] = Jet(0.0, static_cast<int>(k));
  const int nt = static_cast<int>(m_.description().table_axes.size());
  const Eigen::Index n = s_.cols();
  Eigen::Matrix<double, kPlaces, 4> d;
  Eigen::MatrixXd out(n, static_cast<Eigen::Index>(seed.size()));
  for (Eigen::Index r = 0; r < n; ++r) {
    const std::size_t i = static_cast<std::size_t>(r);
    const BallbarSample& smp = samples_[i];
    const detail::AxisStages<Jet> st = detail::axis_stages<Jet>(m_, fx, q, angles_[i], smp.time, motion_[i]);
    d.setZero();
    for (int k = 0; k < nt; ++k) {
      d.row(kAngle + k) = st.angle[k].v.transpose();
      if (st.E[k]) {
        for (int a = 0; a < 3; ++a) d.row(kEt + 3 * k + a) = st.E[k]->t[a].v.transpose();
        d.middleRows<3>(kEw + 3 * k) = small_rotation(st.E[k]->R);
      }
      if (st.K[k]) d.middleRows<3>(kKw + 3 * k) = small_rotation(st.K[k]->R);
    }
    if (st.D[0])
      for (int a = 0; a < 3; ++a) d.row(kD + a) = (*st.D[0])[a].v.transpose();
    const Vec3<Jet> tool = linear_axes_position<Jet>(fx, q, smp.xyz) + tool_offset<Jet>(fx, q);
    for (int a = 0; a < 3; ++a) d.row(kTool + a) = tool[a].v.transpose();
    const Eigen::Matrix<double, 1, 4> row =
        s_.col(r).transpose() * d + ballbar_reading_error<Jet>(fx, q, smp.time).v.transpose();
    out.row(r) = row.head(out.cols());
  }
  return out;
}

}  // namespace rotacal::diagnosis_detail

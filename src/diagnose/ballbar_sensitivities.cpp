// The ballbar candidates' Jacobians by the chain rule (ballbar_sensitivities.hpp).
#include "ballbar_sensitivities.hpp"

#include <ceres/jet.h>

#include <cmath>
#include <cstdio>

#include "../kinematics/stage_instances.hpp"
#include "rotacal/ballbar/problem.hpp"

namespace rotacal {
ROTACAL_STAGE_SCALARS(extern)
}  // namespace rotacal

namespace rotacal::diagnosis_detail {

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
    s[kReading] = 1.0;
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

BallbarPlaces BallbarSensitivities::places(const Effect& effect, const std::vector<int>& seed) const {
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
  // Every place's derivatives first (4 per place and row), then only the places it enters.
  Eigen::Matrix<double, 4 * kPlaces, Eigen::Dynamic> all(4 * kPlaces, n);
  const auto set = [&](Eigen::Index r, int place, const Jet& x) { all.col(r).segment<4>(4 * place) = x.v; };
  for (Eigen::Index r = 0; r < n; ++r) {
    const std::size_t i = static_cast<std::size_t>(r);
    const BallbarSample& smp = samples_[i];
    const detail::AxisStages<Jet> st = detail::axis_stages<Jet>(m_, fx, q, angles_[i], smp.time, motion_[i]);
    all.col(r).setZero();
    for (int k = 0; k < nt; ++k) {
      set(r, kAngle + k, st.angle[k]);
      if (st.E[k]) {
        for (int a = 0; a < 3; ++a) set(r, kEt + 3 * k + a, st.E[k]->t[a]);
        // A left rotation that is the identity at 0: dR = [dw]x, dw = (dR(2,1), dR(0,2), dR(1,0)).
        set(r, kEw + 3 * k, st.E[k]->R(2, 1)), set(r, kEw + 3 * k + 1, st.E[k]->R(0, 2)),
            set(r, kEw + 3 * k + 2, st.E[k]->R(1, 0));
      }
      if (st.K[k])
        set(r, kKw + 3 * k, st.K[k]->R(2, 1)), set(r, kKw + 3 * k + 1, st.K[k]->R(0, 2)),
            set(r, kKw + 3 * k + 2, st.K[k]->R(1, 0));
    }
    if (st.D[0])
      for (int a = 0; a < 3; ++a) set(r, kD + a, (*st.D[0])[a]);
    const Vec3<Jet> tool = linear_axes_position<Jet>(fx, q, smp.xyz) + tool_offset<Jet>(fx, q);
    for (int a = 0; a < 3; ++a) set(r, kTool + a, tool[a]);
    set(r, kReading, ballbar_reading_error<Jet>(fx, q, smp.time));
  }
  BallbarPlaces out;
  out.seeds = static_cast<int>(seed.size());
  for (int p = 0; p < kPlaces; ++p)
    if (all.middleRows(4 * p, out.seeds).cwiseAbs().maxCoeff() > 0.0) out.places.push_back(p);
  out.d.resize(static_cast<Eigen::Index>(out.places.size()) * out.seeds, n);
  for (std::size_t i = 0; i < out.places.size(); ++i)
    out.d.middleRows(static_cast<Eigen::Index>(i) * out.seeds, out.seeds) = all.middleRows(4 * out.places[i], out.seeds);
  return out;
}

std::string BallbarSensitivities::key(const Effect& effect, const std::vector<int>& seed) const {
  std::string k = effect.id();
  for (int s : seed) k += " " + std::to_string(s);
  if (const auto& a = reference_.linear_reference) {
    char buf[80];
    std::snprintf(buf, sizeof buf, " @%.17g,%.17g,%.17g", (*a)[0], (*a)[1], (*a)[2]);
    k += buf;
  }
  return k;
}

Eigen::MatrixXd BallbarSensitivities::columns(const BallbarPlaces& p) const {
  const Eigen::Index n = s_.cols();
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(n, p.seeds);
  for (std::size_t i = 0; i < p.places.size(); ++i)
    for (int k = 0; k < p.seeds; ++k)
      out.col(k).array() += s_.row(p.places[i]).transpose().array() *
                            p.d.row(static_cast<Eigen::Index>(i) * p.seeds + k).transpose().array();
  return out;
}

}  // namespace rotacal::diagnosis_detail

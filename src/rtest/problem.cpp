// SPDX-License-Identifier: BSD-3-Clause
// The R-test problem's layout, arrays and residual model (rtest/problem.hpp).
#include "rotacal/rtest/problem.hpp"

#include <ceres/jet.h>

#include <algorithm>
#include <type_traits>

namespace rotacal {

RtestLayout rtest_layout(MachineType m, const std::vector<std::string>& setups,
                         const RtestBasis* basis, const EffectModel& fx,
                         RtestZeroNames zero_names) {
  RtestLayout L;
  L.errors = add_location_errors(L.all, m);
  // On a machine with head axes the sphere's distance from the controlled point, pivot_length
  // + tool_length, is a parameter of the head (formats.md): its error as tool_offset_Z.
  L.tool = m.has_head()
               ? L.all.add("tool_offset_Z", {"tool_offset_Z"}, {"mm"})
               : L.all.add("tool_offset_Z", std::vector<std::string>{}, std::vector<std::string>{});
  std::vector<std::string> b_names, b_units, c_names, c_units;
  if (basis) {
    // The basis as the machine has it (no rotations in a head axis' map): names and counts alike.
    const RtestBasis b = basis->for_machine(m);
    const std::vector<std::string> names = b.coefficient_names(m);
    const std::size_t nb = static_cast<std::size_t>(b.num_b_coefficients());
    for (std::size_t k = 0; k < names.size(); ++k) {
      const std::string comp = names[k].substr(0, names[k].find('_'));
      (k < nb ? b_names : c_names).push_back(names[k]);
      (k < nb ? b_units : c_units).push_back(comp[0] == 'd' ? "mm" : "rad");
    }
  }
  L.map_tilt = L.all.add("map_tilt", std::move(b_names), std::move(b_units));
  L.map_rot = L.all.add("map_rot", std::move(c_names), std::move(c_units));
  std::vector<std::string> z;
  for (const std::string& s : setups)
    for (const char* a : {"x", "y", "z"})
      z.push_back(zero_names == RtestZeroNames::dotted ? "zero." + s + "." + a
                                                       : std::string("zero_") + a + "#" + s);
  L.zeros = L.all.add("zeros", std::move(z), {"mm"}, 3);
  L.effects = add_effects(L.all, fx);
  return L;
}

RtestArrays rtest_arrays(const RtestSession& session, const std::string& who, bool need_d) {
  RtestArrays a;
  a.machine = session.machine;
  a.setups = session.setups();
  const Eigen::Index n = static_cast<Eigen::Index>(session.samples.size());
  a.xyz.resize(3, n), a.nest.resize(3, n), a.d = Eigen::Matrix3Xd::Zero(3, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const RtestSample& s = session.samples[static_cast<std::size_t>(i)];
    if (need_d && !s.d)
      throw InvalidArgument(who + ": sample " + std::to_string(i) + " of set-up '" + s.setup +
                            "' has no dx,dy,dz (convert raw probe readings first)");
    const auto nest = session.nests.find(s.setup);
    if (nest == session.nests.end())
      throw InvalidArgument(who + ": session.nests: no nest." + s.setup);
    a.setup_of.push_back(
        static_cast<int>(std::find(a.setups.begin(), a.setups.end(), s.setup) - a.setups.begin()));
    a.xyz.col(i) = s.xyz;
    a.nest.col(i) = nest->second;
    if (s.d) a.d.col(i) = *s.d;
    a.angles.push_back(s.angles_rad());
    a.time.push_back(s.time);
  }
  return a;
}

RtestProblem::RtestProblem(const RtestArrays& d, const RtestBasis* basis, EffectModel fx,
                           RtestZeroNames zero_names)
    : d_(d),
      fx_(std::move(fx)),
      L_(rtest_layout(d.machine, d.setups, basis, fx_, zero_names)),
      maps_(basis != nullptr) {
  if (maps_ && !fx_.effects.empty())
    throw InvalidArgument(
        "R-test problem: the smooth maps and catalogue effects are two models of the table "
        "pose; give one");
  if (!maps_) return;
  const RtestBasis b = basis->for_machine(d_.machine);  // as the layout counts its coefficients
  const Eigen::Index n = d_.size(), nb = L_.map_tilt.size, nc = L_.map_rot.size;
  Lb_.resize(6 * n, nb);
  Lc_.resize(6 * n, nc);
  for (Eigen::Index i = 0; i < n; ++i) {
    const RotaryAngles<double>& a = d_.angles[static_cast<std::size_t>(i)];
    b.map_rows(a.tilt, a.rot, Lb_.middleRows<6>(6 * i), Lc_.middleRows<6>(6 * i));
  }
}

void RtestProblem::evaluate(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> r,
                            Eigen::MatrixXd* J) const {
  if (maps_) return evaluate_maps(x, r, J);
  const auto f = [this](Eigen::Index i, const auto* p, auto* out) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(p)>>;
    const Vec3<T> ri = rtest_residual<T>(L_, d_, fx_, p, i);
    for (int a = 0; a < 3; ++a) out[a] = ri[a];
  };
  evaluate_with_jets(f, d_.size(), 3, x, r, J);
}

void RtestProblem::evaluate_maps(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> r,
                                 Eigen::MatrixXd* J) const {
  using Jet = ceres::Jet<double, 21>;  // e (8), w_BY (6), w_CB (6), tool_offset_Z
  const MachineType m = d_.machine;
  const ParameterBlock &E = L_.errors, &B = L_.map_tilt, &C = L_.map_rot, &Z = L_.zeros;
  const Eigen::VectorXd cb = B.of(x), cc = C.of(x);
  const LocationErrors<double> e = LocationErrors<double>::from_ptr(E.ptr(x.data()));
  const double tz = L_.tool.empty() ? 0.0 : x[L_.tool.offset];
  LocationErrors<Jet> ej;
  for (int k = 0; k < 8; ++k) ej.v[k] = Jet(e.v[k], k);
  const Jet tzj(tz, 20);
  for (Eigen::Index i = 0; i < d_.size(); ++i) {
    const std::size_t k = static_cast<std::size_t>(i);
    const Eigen::Index row = 3 * i;
    const auto Lb = Lb_.middleRows<6>(6 * i), Lc = Lc_.middleRows<6>(6 * i);
    const AxisErrors<double> wb = Lb * cb, wc = Lc * cc;
    const Eigen::Index z0 = Z.item_offset(d_.setup_of[k]);  // this pose's probe zero
    const Eigen::Vector3d zero = x.segment<3>(z0);
    const Eigen::Vector3d xyz = d_.xyz.col(i), q = d_.nest.col(i);
    if (!J) {
      r.segment<3>(row) =
          rtest_joint_reading<double>(m, e, wb, wc, tz, d_.angles[k], xyz, q) + zero - d_.d.col(i);
      continue;
    }
    AxisErrors<Jet> wbj, wcj;
    for (int c = 0; c < 6; ++c) wbj[c] = Jet(wb[c], 8 + c), wcj[c] = Jet(wc[c], 14 + c);
    const Vec3<Jet> dm = rtest_joint_reading<Jet>(m, ej, wbj, wcj, tzj, d_.angles[k], xyz, q);
    Eigen::Matrix<double, 3, 21> G;
    for (int a = 0; a < 3; ++a) {
      r[row + a] = dm[a].a + zero[a] - d_.d(a, i);
      G.row(a) = dm[a].v.transpose();
    }
    auto rows = J->middleRows<3>(row);
    E.columns(rows) = G.leftCols<8>();
    if (!L_.tool.empty()) L_.tool.columns(rows) = G.col(20);
    B.columns(rows).noalias() = G.middleCols<6>(8) * Lb;
    C.columns(rows).noalias() = G.middleCols<6>(14) * Lc;
    Z.columns(rows).setZero();
    rows.middleCols<3>(z0).setIdentity();
  }
}

}  // namespace rotacal

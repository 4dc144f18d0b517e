// SPDX-License-Identifier: BSD-3-Clause
// Table motion of two effects (design/table_motion.hpp): the derivative of the table pose as a
// twist, with the location errors and the table point projected out.
#include "rotacal/design/table_motion.hpp"

#include <ceres/jet.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "rotacal/core/error.hpp"
#include "rotacal/core/parameter_layout.hpp"
#include "rotacal/design/format.hpp"
#include "rotacal/kinematics/parameter_blocks.hpp"

namespace rotacal {

namespace {

using Jet1 = ceres::Jet<double, 1>;

// Orthonormal basis of span(M): left singular vectors whose singular value exceeds
// tol (absolute).
Eigen::MatrixXd basis(const Eigen::MatrixXd& M, double tol) {
  if (M.cols() == 0) return Eigen::MatrixXd(M.rows(), 0);
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(M, Eigen::ComputeThinU);
  int r = 0;
  while (r < svd.singularValues().size() && svd.singularValues()[r] > tol) ++r;
  return svd.matrixU().leftCols(r);
}

// The unknowns of the table motion: location errors, the table point's shift (R dq, table
// frame) and fx's parameters.
struct MotionLayout {
  ParameterLayout all;
  ParameterBlock errors, point, effects;
};
MotionLayout motion_layout(MachineType m, const EffectModel& fx) {
  MotionLayout L;
  L.errors = add_location_errors(L.all, m);
  L.point = L.all.add("table_point", {"dq_x", "dq_y", "dq_z"}, {"mm"});
  L.effects = add_effects(L.all, fx);
  return L;
}

// Table motion of every unknown at every pose, 6 rows per pose (omega x r_ref, then v, mm),
// columns in motion_layout order. Each column is one forward-mode pass with a one-wide Jet
// seeded on that unknown.
Eigen::MatrixXd table_motion_columns(const MotionLayout& L, MachineType m, const EffectModel& fx,
                                     const std::vector<RotaryAngles<double>>& poses,
                                     const std::vector<double>& times, double r_ref) {
  const Eigen::Index cols = L.all.size();
  Eigen::MatrixXd G(6 * static_cast<Eigen::Index>(poses.size()), cols);
  for (Eigen::Index c = 0; c < cols; ++c) {
    std::vector<Jet1> x(static_cast<std::size_t>(cols), Jet1(0.0));
    x[static_cast<std::size_t>(c)].v[0] = 1.0;
    const LocationErrors<Jet1> e = LocationErrors<Jet1>::from_ptr(L.errors.ptr(x.data()));
    const Jet1* point = L.point.ptr(x.data());
    const Vec3<Jet1> dq(point[0], point[1], point[2]);
    // Effects' parameters (kinematics reads them only where fx has effects).
    std::vector<Jet1> q(L.effects.ptr(x.data()), L.effects.ptr(x.data()) + L.effects.size);
    if (q.empty()) q.assign(1, Jet1(0.0));
    for (std::size_t i = 0; i < poses.size(); ++i) {
      Pose<Jet1> T = table_pose<Jet1>(m, e, fx, q.data(), poses[i], times[i]);
      T.t += T.R * dq;  // the table point moved in the table frame
      Eigen::Matrix3d R0, dR;
      Eigen::Vector3d t0, dt;
      for (int a = 0; a < 3; ++a) {
        t0[a] = T.t[a].a;
        dt[a] = T.t[a].v[0];
        for (int b = 0; b < 3; ++b) R0(a, b) = T.R(a, b).a, dR(a, b) = T.R(a, b).v[0];
      }
      const Eigen::Matrix3d W = dR * R0.transpose();  // skew(omega)
      const Eigen::Vector3d w(W(2, 1), W(0, 2), W(1, 0));
      const Eigen::Index row = 6 * static_cast<Eigen::Index>(i);
      G.block<3, 1>(row, c) = w * r_ref;
      G.block<3, 1>(row + 3, c) = dt - w.cross(t0);
    }
  }
  return G;
}

std::string deg_range(std::array<double, 2> r) {
  return fixed_text(r[0], 0) + ".." + fixed_text(r[1], 0) + " deg";
}

}  // namespace

TableMotionOverlap table_motion_overlap(MachineType m, const Effect& a, const Effect& b,
                                        std::array<double, 2> tilt, double duration_s,
                                        double r_ref) {
  for (const Effect* f : {&a, &b})
    if (!f->applies_to(m))
      throw InvalidArgument("effect " + f->id() + " does not exist on a " + to_string(m));
  if (!(tilt[0] < tilt[1]))
    throw InvalidArgument("table_motion_overlap: the tilt limits must be min < max deg");
  if (!(duration_s >= 0.0) || !std::isfinite(duration_s))
    throw InvalidArgument("table_motion_overlap: the duration must be >= 0 s");
  if (!(r_ref > 0.0))
    throw InvalidArgument("table_motion_overlap: the reference radius must be > 0 mm");
  // 19 tilt angles x 24 C angles x 3 times: every harmonic up to 4 is resolved on both axes.
  std::vector<RotaryAngles<double>> poses;
  std::vector<double> times;
  const double deg = M_PI / 180.0;
  for (int it = 0; it < 3; ++it)
    for (int i = 0; i < 19; ++i)
      for (int k = 0; k < 24; ++k) {
        poses.push_back({(tilt[0] + (tilt[1] - tilt[0]) * i / 18.0) * deg, k * 15.0 * deg});
        times.push_back(duration_s * it / 2.0);
      }
  EffectModel fx;
  fx.effects = {a, b};
  const MotionLayout L = motion_layout(m, fx);
  const Eigen::MatrixXd G = table_motion_columns(L, m, fx, poses, times, r_ref);
  const Eigen::Index na = a.num_params(), nb = b.num_params();
  const Eigen::MatrixXd E1 = G.middleCols(L.effects.offset, na),
                        E2 = G.middleCols(L.effects.offset + na, nb);
  // The location errors and the table point: the columns before the effects.
  const Eigen::MatrixXd G0 = G.leftCols(L.effects.offset);
  const double n1 = E1.norm(), n2 = E2.norm(), scale = std::max(G0.norm(), 1.0);
  TableMotionOverlap out;
  out.moves_table_first = n1 > 1e-12 * scale;
  out.moves_table_second = n2 > 1e-12 * scale;
  const std::string range = "tilt " + deg_range(tilt) + ", C over a full turn, time 0.." +
                            fixed_text(duration_s, 0) + " s";
  if (!out.moves_table_first || !out.moves_table_second) {
    out.why =
        (out.moves_table_first ? b : a).id() +
        " does not move the table (it acts on the tool side or in the instrument), so the table "
        "motion cannot decide: an added test is searched";
    return out;
  }
  const Eigen::MatrixXd Q = basis(G0, 1e-10 * G0.norm());
  const Eigen::MatrixXd A1 = E1 - Q * (Q.transpose() * E1), A2 = E2 - Q * (Q.transpose() * E2);
  const Eigen::MatrixXd U1 = basis(A1, 1e-7 * n1), U2 = basis(A2, 1e-7 * n2);
  out.first_is_location = U1.cols() == 0;
  out.second_is_location = U2.cols() == 0;
  if (out.first_is_location || out.second_is_location) {
    out.same_motion = true;
    out.cosine = 1.0;
    const Effect& loc = out.first_is_location ? a : b;
    out.why =
        "at every pose (" + range + ") " + loc.id() +
        " moves the table only as the location errors and the set-up's table point do: every "
        "instrument reads the table's motion and fits those, so no test determines it, whatever "
        "the other effect; only changing its cause can (" +
        loc.cause() + ")";
    return out;
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(U1.transpose() * U2);
  out.cosine = std::min(1.0, svd.singularValues()[0]);
  out.same_motion = out.cosine >= 1.0 - 1e-6;
  // Nested: all principal angles zero (the smallest cosine 1), so the span of the one with fewer
  // motions lies in the other's.
  const bool within = svd.singularValues().minCoeff() >= 1.0 - 1e-6;
  out.first_within_second = within && U1.cols() < U2.cols();
  out.second_within_first = within && U2.cols() < U1.cols();
  std::ostringstream w;
  w.precision(6);
  if (out.same_motion) {
    w << "at every pose (" << range << ") a combination of " << a.id()
      << "'s parameters moves the table exactly as one of " << b.id()
      << "'s does, together with the location errors and the set-up's table point (cosine of their "
         "table motions "
      << std::fixed << out.cosine
      << "): every instrument reads the table's motion, so no test can tell them apart; only "
         "changing "
         "the cause of one of them can ("
      << a.id() << ": " << a.cause() << "; " << b.id() << ": " << b.cause() << ")";
  } else {
    w << "their table motions differ (largest cosine " << std::fixed << out.cosine
      << " once the location errors and the table point are taken out, over " << range
      << "): a test that reads the difference separates them";
  }
  out.why = w.str();
  return out;
}

}  // namespace rotacal

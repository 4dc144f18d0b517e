// SPDX-License-Identifier: BSD-3-Clause
// The ballbar residual model's kernels (length_model.hpp), compiled once for the library.
#include "length_model.hpp"

#include <algorithm>

#include "length_chain.hpp"

// Inline every call in the row kernel: GCC otherwise keeps the rotation and its derivative
// products as calls that pass Lanes vectors through memory. Not under AddressSanitizer: the
// flattened kernel, instrumented, is what made identify_joint.cpp and monte_carlo.cpp take
// minutes to compile in the sanitizer build, where speed does not matter.
#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define ROTACAL_SANITIZED 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__)
#define ROTACAL_SANITIZED 1
#endif
#if defined(__GNUC__) && !defined(ROTACAL_SANITIZED)
#define ROTACAL_FLATTEN __attribute__((flatten))
#else
#define ROTACAL_FLATTEN
#endif

namespace rotacal {

// What the chain takes from the parameter vector, evaluated once per evaluation: the actual
// lines of both axes (point, unit direction, 1 / |direction|), the pivot and the tool vector;
// on doubles, then the same in every lane (Lanes) for the rows.
template <typename S>
struct BallbarLengthModel::Chain {
  Vec3<S> point[2], u[2];
  S inv_norm[2] = {S(1.0), S(1.0)};
  // d(line point)/d(position errors) and d(unit direction)/d(direction errors) =
  // (I - u u^T) / |direction| * direction_basis, 3 x 2 each.
  Eigen::Matrix<S, 3, 2> d_point[2], d_unit[2];
  Vec3<S> pivot, tool;
  S length_offset = S(0.0);
  int tool_z_col = -1, length_col = -1;
};

BallbarLengthModel::BallbarLengthModel(const BallbarArrays& d, const EffectModel& fx)
    : d_(d),
      fx_(fx),
      L_(ballbar_layout(d.machine, fx)),
      analytic_(analytic_supported(fx)),
      chain_(!analytic_ && length_chain::supports(d.machine)),
      nt_(static_cast<int>(d.machine.description().table_axes.size())) {
  if (analytic_) commanded_sincos();
  for (const Effect& f : fx.effects)
    if (f.depends_on_motion() && d.motion.size() != static_cast<std::size_t>(d.size()))
      throw InvalidArgument("ballbar fit: effect " + f.id() +
                            " needs the motion of the axes, which these "
                            "arrays were built without (ballbar_arrays with_motion)");
}

void BallbarLengthModel::evaluate(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> r,
                                  Eigen::MatrixXd* J) const {
  if (analytic_) {
    evaluate_rows(chain_at(x), d_.size(), [](Eigen::Index k) { return k; }, r, J);
    return;
  }
  if (J && chain_) {
    evaluate_chain(x, r, *J);
    return;
  }
  evaluate_with_jets([this](Eigen::Index i, const auto* p, auto* out) { sample(i, p, out); },
                     d_.size(), 1, x, r, J);
}

bool BallbarLengthModel::evaluate_subset(const Eigen::VectorXd& x, Eigen::Index stride,
                                         Eigen::VectorXd& r, Eigen::MatrixXd* J) const {
  const Eigen::Index m = (d_.size() + stride - 1) / stride;
  r.resize(m);
  if (J) J->resize(m, num_parameters());
  if (analytic_) {
    evaluate_rows(chain_at(x), m, [stride](Eigen::Index k) { return k * stride; }, r, J);
    return true;
  }
  evaluate_with_jets(
      [this, stride](Eigen::Index i, const auto* p, auto* out) { sample(i * stride, p, out); }, m,
      1, x, r, J);
  return true;
}

void BallbarLengthModel::evaluate_jets(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> r,
                                       Eigen::MatrixXd* J) const {
  evaluate_with_jets([this](Eigen::Index i, const auto* p, auto* out) { sample(i, p, out); },
                     d_.size(), 1, x, r, J);
}

// At most one tool length and one bar length offset (analytic_lanes writes one column each).
bool BallbarLengthModel::analytic_supported(const EffectModel& fx) {
  int tool = 0, length = 0;
  for (const Effect& f : fx.effects) {
    if (f.kind == EffectKind::tool_offset_Z)
      ++tool;
    else if (f.kind == EffectKind::ballbar_length_offset)
      ++length;
    else
      return false;
  }
  return tool <= 1 && length <= 1;
}

// cos and sin of every sample's commanded angle of chain axes 0 and 1 (rows c0, s0, c1, s1):
// they do not depend on the parameters, and were a quarter of a fit's time (perf, table2).
// In a test one axis mostly stands still, so an angle equal to the previous sample's is copied.
void BallbarLengthModel::commanded_sincos() {
  const Eigen::Index n = d_.size();
  cs_.resize(4, n);
  const int rot = d_.machine.rot_index();
  for (int k = 0; k < 2; ++k) {
    double last = 0.0, c = 1.0, s = 0.0;
    for (Eigen::Index i = 0; i < n; ++i) {
      const RotaryAngles<double>& a = d_.angles[static_cast<std::size_t>(i)];
      const double angle = k == rot ? a.rot : a.tilt;  // chain_angle
      if (i == 0 || angle != last) last = angle, c = std::cos(angle), s = std::sin(angle);
      cs_(2 * k, i) = c;
      cs_(2 * k + 1, i) = s;
    }
  }
}

BallbarLengthModel::Chain<Lanes> BallbarLengthModel::in_lanes(const Chain<double>& c) {
  Chain<Lanes> out;
  for (int k = 0; k < 2; ++k) {
    out.point[k] = c.point[k].cast<Lanes>();
    out.u[k] = c.u[k].cast<Lanes>();
    out.inv_norm[k] = Lanes(c.inv_norm[k]);
    out.d_point[k] = c.d_point[k].cast<Lanes>();
    out.d_unit[k] = c.d_unit[k].cast<Lanes>();
  }
  out.pivot = c.pivot.cast<Lanes>();
  out.tool = c.tool.cast<Lanes>();
  out.length_offset = Lanes(c.length_offset);
  out.tool_z_col = c.tool_z_col, out.length_col = c.length_col;
  return out;
}

// Residuals (and Jacobian rows) of samples sample_of(0 .. m-1), four at a time in Lanes (a
// sample at a time on doubles, 1,804 Jacobian rows took 139 us, the largest part of a fit of
// ballbar_ac_table2.csv). A short last block repeats its last sample in the unused lanes.
template <typename SampleOf>
void BallbarLengthModel::evaluate_rows(const Chain<double>& chain, Eigen::Index m,
                                       SampleOf sample_of, Eigen::Ref<Eigen::VectorXd> r,
                                       Eigen::MatrixXd* J) const {
  const Chain<Lanes> ch = in_lanes(chain);
  const int cols = num_parameters();
  JacobianLanes row;
  Eigen::Index idx[Lanes::kSize];
  for (Eigen::Index k0 = 0; k0 < m; k0 += Lanes::kSize) {
    const int count = static_cast<int>(std::min<Eigen::Index>(Lanes::kSize, m - k0));
    for (int l = 0; l < Lanes::kSize; ++l) idx[l] = sample_of(k0 + std::min(l, count - 1));
    const Lanes rl =
        J ? analytic_lanes<true>(ch, idx, &row) : analytic_lanes<false>(ch, idx, nullptr);
    for (int l = 0; l < count; ++l) r[k0 + l] = rl[l];
    if (J)
      for (int c = 0; c < cols; ++c)
        for (int l = 0; l < count; ++l) (*J)(k0 + l, c) = row[c][l];
  }
}

BallbarLengthModel::Chain<double> BallbarLengthModel::chain_at(const Eigen::VectorXd& x) const {
  const MachineType m = d_.machine;
  const LocationErrors<double> e(L_.errors.of<8>(x));
  Chain<double> ch;
  double tool_z = 0.0;
  for (std::size_t k = 0; k < fx_.effects.size(); ++k) {
    const int col = static_cast<int>(L_.effects.offset) + fx_.offset(k);
    if (fx_.effects[k].kind == EffectKind::tool_offset_Z)
      tool_z += x[col], ch.tool_z_col = col;
    else
      ch.length_offset = x[col], ch.length_col = col;
  }
  for (int k = 0; k < 2; ++k) {
    const AxisLine<double> L = axis_line(m, k, e);
    ch.point[k] = L.point;
    ch.inv_norm[k] = 1.0 / L.direction.norm();
    ch.u[k] = L.direction * ch.inv_norm[k];
    const RotaryAxis& a = m.description().axis(k);
    ch.d_point[k] = a.position_basis;
    ch.d_unit[k] = (Eigen::Matrix3d::Identity() - ch.u[k] * ch.u[k].transpose()) * ch.inv_norm[k] *
                   a.direction_basis;
  }
  ch.pivot = L_.pivots.of<3>(x);
  ch.tool = tool_vector<double>(m, 0.0) + Eigen::Vector3d(0.0, 0.0, tool_z);
  return ch;
}

// Residuals of the four samples idx, and with WithJacobian their Jacobian rows by the chain
// rule (see the class comment).
template <bool WithJacobian>
ROTACAL_FLATTEN Lanes BallbarLengthModel::analytic_lanes(const Chain<Lanes>& ch,
                                                         const Eigen::Index (&idx)[Lanes::kSize],
                                                         JacobianLanes* J) const {
  using Row = Eigen::Matrix<Lanes, 1, 3>;
  Lanes cs[4], measured;
  Vec3<Lanes> xyz;
  for (int l = 0; l < Lanes::kSize; ++l) {
    const Eigen::Index i = idx[l];
    for (int c = 0; c < 4; ++c) cs[c][l] = cs_(c, i);
    for (int a = 0; a < 3; ++a) xyz[a][l] = d_.xyz(a, i);
    measured[l] = d_.length[i];
  }
  const int nt = nt_;
  LineRotationDerivatives<Lanes> D[2];
  const auto rotate = [&](int k, const Vec3<Lanes>& q) -> Vec3<Lanes> {
    if constexpr (WithJacobian)
      return (D[k] = rotate_point_about_unit_line_derivatives<Lanes>(
                  ch.point[k], ch.u[k], ch.inv_norm[k], cs[2 * k], cs[2 * k + 1], q))
          .f;
    else
      return rotate_point_about_unit_line<Lanes>(ch.point[k], ch.u[k], cs[2 * k], cs[2 * k + 1], q);
  };
  // Table side: the pivot through the table axes, innermost first.
  Vec3<Lanes> P = ch.pivot;
  for (int k = nt - 1; k >= 0; --k) P = rotate(k, P);
  // Tool side: the tool vector through the head axes, innermost first.
  Vec3<Lanes> v = ch.tool;
  for (int k = 1; k >= nt; --k) v = rotate(k, v);
  const Vec3<Lanes> b = xyz + v;
  const Lanes length = (b - P).norm();
  // The residual from the same chain: the ball points above are the one model's rotations
  // composed as predicted_length composes them (the Jets test checks r as well as J).
  const Lanes r = length + ch.length_offset - measured;
  if constexpr (WithJacobian) {
    const Vec3<Lanes> u = (b - P) / length;
    // dL/d(line k) = +-u^T (outer rotations) dD_k; the table side enters with a minus. Every
    // column is written: the 8 location errors (axis k's position pair, then its direction
    // pair), the pivot, and the offsets this model has.
    const Eigen::Index e0 = L_.errors.offset;
    const auto line_columns = [&](int k, const Row& w, const Row& wq) {
      J->template segment<2>(e0 + 4 * k) = D[k].times_point(w, wq) * ch.d_point[k];
      J->template segment<2>(e0 + 4 * k + 2) = D[k].times_unit_direction(w) * ch.d_unit[k];
    };
    Row w = -u.transpose();
    for (int k = 0; k < nt; ++k) {
      const Row wq = D[k].times_q(w);
      line_columns(k, w, wq);
      w = wq;
    }
    J->template segment<3>(L_.pivots.offset) = w;  // d/dpivot
    w = u.transpose();
    for (int k = nt; k < 2; ++k) {
      const Row wq = D[k].times_q(w);
      line_columns(k, w, wq);
      w = wq;
    }
    if (ch.tool_z_col >= 0) (*J)[ch.tool_z_col] = w.z();
    if (ch.length_col >= 0) (*J)[ch.length_col] = Lanes(1.0);
  }
  return r;
}

// L_model - L_measured of sample i, on double or Jets: the problem's one residual.
template <typename T>
void BallbarLengthModel::sample(Eigen::Index i, const T* p, T* out) const {
  out[0] = ballbar_residual<T>(L_, d_, fx_, p, i);
}

}  // namespace rotacal

// Diagnosis of ballbar circular tests: the separate catalogue of linear-axis causes, its
// columns (first-order change of the reading per unit parameter), and the forward selection
// with the thresholds of the rotary diagnosis.
#include "rotacal/diagnose/circular_diagnosis.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <set>

#include "rotacal/core/error.hpp"
#include "rotacal/core/stats.hpp"
#include "scoring.hpp"

namespace rotacal {

namespace {

constexpr double kPi = 3.14159265358979323846;
const char* kAxes = "XYZ";

std::string axis_name(int i) { return std::string(1, kAxes[i]); }

// Plausible sizes per unit, for visibility (see CircularDiagnosisOptions::min_visible_chi2).
double magnitude(const std::string& unit) {
  if (unit == "rad") return 50e-6;
  if (unit == "mm/mm") return 50e-6;
  if (unit == "s") return 1e-3;
  return 0.005;  // mm
}

}  // namespace

// ----------------------------------------------------------------------------- catalogue

std::string CircularEffect::id() const {
  switch (kind) {
    case CircularEffectKind::squareness:
      return "squareness_" + to_string(plane);
    case CircularEffectKind::scale_mismatch:
      return "scale_mismatch_" + to_string(plane);
    case CircularEffectKind::straightness:
      return "straightness_" + axis_name(direction) + axis_name(axis);
    case CircularEffectKind::backlash:
      return "backlash_" + axis_name(axis);
    case CircularEffectKind::reversal_spike:
      return "reversal_spike_" + axis_name(axis);
    case CircularEffectKind::servo_mismatch:
      return "servo_mismatch_" + to_string(plane);
    case CircularEffectKind::cyclic_error:
      return "cyclic_error_" + axis_name(axis);
  }
  ROTACAL_ASSERT(false);
  return {};
}

CircularEffect CircularEffect::parse(const std::string& id) {
  for (const CircularEffect& e : circular_catalogue())
    if (e.id() == id) return e;
  std::string known;
  for (const CircularEffect& e : circular_catalogue())
    known += (known.empty() ? "" : ", ") + e.id();
  throw InvalidArgument("unknown circular-test effect '" + id + "' (known: " + known + ")");
}

std::vector<std::string> CircularEffect::param_names() const {
  switch (kind) {
    case CircularEffectKind::squareness:
      return {"s"};
    case CircularEffectKind::scale_mismatch:
      return {"dk"};
    case CircularEffectKind::straightness:
      return {"c2"};
    case CircularEffectKind::backlash:
      return {"b", "delay"};
    case CircularEffectKind::reversal_spike:
      return {"h", "tau", "delay"};
    case CircularEffectKind::servo_mismatch:
      return {"dtau"};
    case CircularEffectKind::cyclic_error:
      return {"c", "d"};
  }
  return {};
}

std::vector<std::string> CircularEffect::param_units() const {
  switch (kind) {
    case CircularEffectKind::squareness:
      return {"rad"};
    case CircularEffectKind::scale_mismatch:
      return {"mm/mm"};
    case CircularEffectKind::straightness:
      return {"mm"};
    case CircularEffectKind::backlash:
      return {"mm", "s"};
    case CircularEffectKind::reversal_spike:
      return {"mm", "s", "s"};
    case CircularEffectKind::servo_mismatch:
      return {"s"};
    case CircularEffectKind::cyclic_error:
      return {"mm", "mm"};
  }
  return {};
}

std::string CircularEffect::cause() const {
  const auto ax = plane_axes(plane);
  const std::string u = axis_name(ax[0]), v = axis_name(ax[1]);
  switch (kind) {
    case CircularEffectKind::squareness:
      return "axes " + u + " and " + v + " are not perpendicular (" + u + " moves by s per mm of " +
             v + "): an ellipse at 45 deg, the same in both directions";
    case CircularEffectKind::scale_mismatch:
      return "axes " + u + " and " + v +
             " scale differently (screw pitch error, encoder, thermal "
             "expansion of one axis): an ellipse along the axes";
    case CircularEffectKind::straightness:
      return "axis " + axis_name(axis) + " is not straight in " + axis_name(direction) +
             " (a bowed guideway, ISO 230-1 E_" + axis_name(direction) + axis_name(axis) + ")";
    case CircularEffectKind::backlash:
      return "lost motion of axis " + axis_name(axis) +
             " at reversal (screw or nut backlash, worn drive): a step at its reversal points, "
             "opposite in the two directions";
    case CircularEffectKind::reversal_spike:
      return "axis " + axis_name(axis) +
             " sticks when it reverses (friction, the servo's integral "
             "action catching up): an outward spike decaying after its reversal points";
    case CircularEffectKind::servo_mismatch:
      return "the position loops of " + u + " and " + v +
             " lag differently (unequal servo gains): a "
             "45 deg ellipse that tilts the other way when the direction reverses, growing with "
             "feed";
    case CircularEffectKind::cyclic_error:
      return "cyclic error of axis " + axis_name(axis) +
             " periodic with its screw lead (screw "
             "runout, thrust bearing, encoder interpolation)";
  }
  return {};
}

std::vector<CircularEffect> circular_catalogue() {
  std::vector<CircularEffect> out;
  const CircularPlane planes[] = {CircularPlane::XY, CircularPlane::YZ, CircularPlane::ZX};
  for (CircularEffectKind k : {CircularEffectKind::squareness, CircularEffectKind::scale_mismatch})
    for (CircularPlane p : planes) out.push_back({k, p, 0, 0});
  for (int A = 0; A < 3; ++A)
    for (int D = 0; D < 3; ++D)
      if (D != A) out.push_back({CircularEffectKind::straightness, CircularPlane::XY, A, D});
  for (CircularEffectKind k : {CircularEffectKind::backlash, CircularEffectKind::reversal_spike})
    for (int a = 0; a < 3; ++a) out.push_back({k, CircularPlane::XY, a, 0});
  for (CircularPlane p : planes) out.push_back({CircularEffectKind::servo_mismatch, p, 0, 0});
  for (int a = 0; a < 3; ++a)
    out.push_back({CircularEffectKind::cyclic_error, CircularPlane::XY, a, 0});
  return out;
}

// ----------------------------------------------------------------------------- columns

namespace {

using diagnosis_detail::orthonormal_basis;
using diagnosis_detail::solve_ls;

struct Rows {
  std::size_t n = 0;
  Eigen::VectorXd y;  // reading - L0, mm
  std::vector<std::string> group;
  std::vector<double> time;
  std::vector<int> run;
  std::vector<CircularPlane> plane;
  std::vector<std::array<int, 2>> axes_uv;  // plane_axes of each row's plane
  std::vector<double> theta, omega;
  std::vector<double> cos_theta, sin_theta;  // of theta, computed once: every column uses them
  std::vector<Eigen::Vector3d> axes;         // commanded machine axes, mm
  // Rows of run k: [run_first[k], run_first[k] + run_count[k]) (gather appends runs in order).
  std::vector<Eigen::Index> run_first, run_count;
  Eigen::Vector3d centre_axes = Eigen::Vector3d::Zero();
  double radius = 0.0;
  std::set<CircularPlane> planes;
  std::set<int> moving_axes;
  std::set<CircularDirection> directions;
  std::size_t runs = 0;
};

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

// d reading / d parameter (mm per parameter unit) of an entry's linear parameters; backlash and
// spikes with the axis reversing `delay` (s) after the commanded reversal (its servo lag), a
// spike decaying with `tau` (s).
Eigen::MatrixXd effect_columns(const Rows& R, const CircularEffect& e, const Eigen::Vector3d& pitch,
                               double tau = 0.0, double delay = 0.0) {
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

// Whitening of columns by the current noise model (identity when none).
// Whitening of columns (mm) to unit-variance units: the AR whitener of a coloured noise model,
// or 1 / sigma of a white one, so that squared norms are chi-squares (visibility, F, BIC).
struct Whitening {
  std::unique_ptr<ArWhitener> w;
  double scale = 1.0;  // 1 / sigma (mm) when w is null
  Eigen::MatrixXd operator()(Eigen::MatrixXd M) const {
    if (w && M.cols() > 0)
      w->apply(M);
    else
      M *= scale;
    return M;
  }
  void set(const NoiseModel& nm) {
    w = nm.white() ? nullptr : std::make_unique<ArWhitener>(nm);
    scale = nm.white() && nm.sigma_um > 0.0 ? 1.0 / (nm.sigma_um * 1e-3) : 1.0;
    ++version;
  }
  /// White noise of sigma 1 / s (mm).
  void set_scale(double s) {
    w.reset();
    scale = s;
    ++version;
  }
  int version = 0;  ///< changes with the whitening (keys the baseline cache)
  /// The whitened baseline B_w and its per-run orthonormal bases under this whitening: B is the
  /// same in every fit, so they are computed once per whitening (baseline()).
  struct Baseline {
    int version = -1;
    Eigen::MatrixXd Bw;
    std::vector<Eigen::MatrixXd> qb;
  };
  const Baseline& baseline(const struct Rows& R, const Eigen::Ref<const Eigen::MatrixXd>& B) const;

 private:
  mutable Baseline baseline_;
};

// Least squares against the model's columns M = [B | E] exploits the baseline's structure: B
// holds three columns per run that are zero outside that run's rows, and stay so whitened (the
// whitener works within each run's stream). The baseline is projected out run by run (an
// n_k x 3 QR each), then only the few effect columns E need a QR over all n rows: O(n e^2)
// instead of O(n (3 runs + e)^2), the same least-squares solution and span (Frisch-Waugh).
//
// An effect column that the baseline absorbs leaves a remainder of rounding size; the QR would
// scale it back up to unit norm and take it for a direction, so a remainder below 1e-9 of the
// column's norm (the rank threshold of solve_ls / orthonormal_basis) is set to zero.
void drop_absorbed(Eigen::MatrixXd& E, const Eigen::VectorXd& norm_before) {
  for (Eigen::Index j = 0; j < E.cols(); ++j)
    if (!(E.col(j).norm() > 1e-9 * norm_before[j])) E.col(j).setZero();
}

// Per-run orthonormal bases of the baseline columns of (whitened) M, rows by `first`/`count`.
std::vector<Eigen::MatrixXd> baseline_bases(const std::vector<Eigen::Index>& first,
                                            const std::vector<Eigen::Index>& count,
                                            const Eigen::MatrixXd& M) {
  ROTACAL_ASSERT(M.cols() >= static_cast<Eigen::Index>(3 * first.size()));
  std::vector<Eigen::MatrixXd> q(first.size());
  for (std::size_t k = 0; k < first.size(); ++k)
    q[k] = orthonormal_basis(M.block(first[k], static_cast<Eigen::Index>(3 * k), count[k], 3));
  return q;
}

const Whitening::Baseline& Whitening::baseline(const Rows& R,
                                               const Eigen::Ref<const Eigen::MatrixXd>& B) const {
  if (baseline_.version != version) {
    baseline_.Bw = (*this)(Eigen::MatrixXd(B));
    baseline_.qb = baseline_bases(R.run_first, R.run_count, baseline_.Bw);
    baseline_.version = version;
  }
  return baseline_;
}

void remove_baseline(const std::vector<Eigen::MatrixXd>& qb, const std::vector<Eigen::Index>& first,
                     const std::vector<Eigen::Index>& count, Eigen::MatrixXd& X) {
  for (std::size_t k = 0; k < qb.size(); ++k) {
    auto block = X.middleRows(first[k], count[k]);
    block -= qb[k] * (qb[k].transpose() * block);
  }
}

// Least-squares coefficients of y on [B | E] (both already whitened; qb: B's per-run bases),
// rows of run k at [first[k], first[k] + count[k]).
Eigen::VectorXd block_solve(const std::vector<Eigen::Index>& first,
                            const std::vector<Eigen::Index>& count, const Eigen::MatrixXd& B,
                            const std::vector<Eigen::MatrixXd>& qb, const Eigen::MatrixXd& E,
                            const Eigen::VectorXd& y) {
  const Eigen::Index nb = B.cols(), ne = E.cols();
  Eigen::VectorXd beta(nb + ne);
  Eigen::VectorXd r = y;
  if (ne > 0) {
    Eigen::MatrixXd Ep = E;
    const Eigen::VectorXd norms = Ep.colwise().norm().transpose();
    Eigen::MatrixXd yp = y;
    remove_baseline(qb, first, count, Ep);
    remove_baseline(qb, first, count, yp);
    drop_absorbed(Ep, norms);
    beta.tail(ne) = solve_ls(Ep, yp.col(0));
    r -= E * beta.tail(ne);
  }
  for (std::size_t k = 0; k < first.size(); ++k)
    beta.segment(static_cast<Eigen::Index>(3 * k), 3) =
        solve_ls(B.block(first[k], static_cast<Eigen::Index>(3 * k), count[k], 3),
                 r.segment(first[k], count[k]));
  return beta;
}

// The same for M = [B | E] in one matrix.
Eigen::VectorXd block_solve(const std::vector<Eigen::Index>& first,
                            const std::vector<Eigen::Index>& count, const Eigen::MatrixXd& M,
                            const Eigen::VectorXd& y) {
  const Eigen::Index nb = static_cast<Eigen::Index>(3 * first.size());
  return block_solve(first, count, M.leftCols(nb), baseline_bases(first, count, M),
                     M.rightCols(M.cols() - nb), y);
}

// Orthonormal basis of the span of whitened model columns [B | E], kept as the per-run bases
// of the baseline and one of the effect columns with the baseline projected out (orthogonal to
// them): projecting a column out costs O(n (3 + e)), not O(n (3 runs + e)).
class ModelBasis {
 public:
  ModelBasis(const Rows& R, const Eigen::MatrixXd& Mw)
      : first_(&R.run_first),
        count_(&R.run_count),
        qb_(baseline_bases(R.run_first, R.run_count, Mw)) {
    const Eigen::Index nb = static_cast<Eigen::Index>(3 * R.runs);
    Eigen::MatrixXd E = Mw.rightCols(Mw.cols() - nb);
    const Eigen::VectorXd norms = E.colwise().norm().transpose();
    remove_baseline(qb_, *first_, *count_, E);
    drop_absorbed(E, norms);
    qe_ = orthonormal_basis(E);
  }
  /// Dimension of the span.
  int rank() const {
    Eigen::Index r = qe_.cols();
    for (const Eigen::MatrixXd& q : qb_) r += q.cols();
    return static_cast<int>(r);
  }
  /// X less its projection on the span.
  Eigen::MatrixXd project_out(Eigen::MatrixXd X) const {
    remove_baseline(qb_, *first_, *count_, X);
    if (qe_.cols() > 0) X -= qe_ * (qe_.transpose() * X);
    return X;
  }

 private:
  const std::vector<Eigen::Index>* first_;
  const std::vector<Eigen::Index>* count_;
  std::vector<Eigen::MatrixXd> qb_;
  Eigen::MatrixXd qe_;
};

// Least-squares fits of y on the baseline and subsets of the effect columns, all from one QR:
// with P the whitened baseline projected out run by run, [P E_w | P y_w] = Q Rf, and the fit on
// effect columns S leaves |Rf_S x - rf_y|^2 minimised (Q has orthonormal columns), a problem of
// e + 1 rows instead of n.
class CompressedFit {
 public:
  CompressedFit(const Rows& R, const Eigen::MatrixXd& Mw, const Eigen::VectorXd& yw)
      : nb_(static_cast<Eigen::Index>(3 * R.runs)) {
    const std::vector<Eigen::MatrixXd> qb = baseline_bases(R.run_first, R.run_count, Mw);
    const Eigen::Index e = Mw.cols() - nb_;
    Eigen::MatrixXd X(Mw.rows(), e + 1);
    X.leftCols(e) = Mw.rightCols(e);
    X.col(e) = yw;
    const Eigen::VectorXd norms = X.colwise().norm().transpose();
    remove_baseline(qb, R.run_first, R.run_count, X);
    Eigen::MatrixXd E = X.leftCols(e);
    drop_absorbed(E, norms.head(e));
    X.leftCols(e) = E;
    const Eigen::HouseholderQR<Eigen::MatrixXd> qr(X);
    const Eigen::Index rows = std::min<Eigen::Index>(X.rows(), e + 1);
    rf_ = qr.matrixQR().topRows(rows).triangularView<Eigen::Upper>();
  }
  /// Whitened residual sum of squares of the fit without the model columns [from, from + count)
  /// (indices into Mw; effect columns only).
  double rss_without(Eigen::Index from, Eigen::Index count) const {
    const Eigen::Index e = rf_.cols() - 1;
    ROTACAL_ASSERT(from >= nb_ && from + count <= nb_ + e);
    Eigen::MatrixXd S(rf_.rows(), e - count);
    Eigen::Index c = 0;
    for (Eigen::Index j = 0; j < e; ++j)
      if (j < from - nb_ || j >= from - nb_ + count) S.col(c++) = rf_.col(j);
    const Eigen::VectorXd ry = rf_.col(e);
    if (S.cols() == 0) return ry.squaredNorm();
    return (S * solve_ls(S, ry) - ry).squaredNorm();
  }

 private:
  Eigen::Index nb_;
  Eigen::MatrixXd rf_;
};

// Blocked cross-validated RMS (um) of predicting y from the columns M = [B | E] (unwhitened,
// as diagnosis_detail::cv_rms_um, which it equals): refit on all blocks but one of every run
// by block_solve, predict the left-out rows.
double cv_rms_um(const Rows& R, const Eigen::MatrixXd& M, const Eigen::VectorXd& y,
                 const std::vector<int>& fold, int K) {
  double ss = 0.0;
  std::size_t n = 0;
  for (int k = 0; k < K; ++k) {
    std::vector<Eigen::Index> tr, te;
    std::vector<Eigen::Index> first(R.runs, 0), count(R.runs, 0);
    for (std::size_t i = 0; i < fold.size(); ++i) {
      if (fold[i] == k) {
        te.push_back(static_cast<Eigen::Index>(i));
      } else {
        const std::size_t run = static_cast<std::size_t>(R.run[i]);
        if (count[run] == 0) first[run] = static_cast<Eigen::Index>(tr.size());
        ++count[run];
        tr.push_back(static_cast<Eigen::Index>(i));
      }
    }
    if (te.empty() || tr.empty()) continue;
    const Eigen::VectorXd d =
        block_solve(first, count, M(tr, Eigen::all), y(tr));
    ss += (y(te) - M(te, Eigen::all) * d).squaredNorm();
    n += te.size();
  }
  return n ? std::sqrt(ss / static_cast<double>(n)) * 1e3 : 0.0;
}

// Noise sigma (mm) from successive differences within each run: sigma^2 = sum (r_{i+1} -
// r_i)^2 / (2 (n - 1)). Smooth systematic errors barely move it (the rotary diagnosis' rule);
// correlated noise makes it smaller than the marginal sigma, so tests on it are lenient,
// which the AR steps after it correct.
double difference_sigma(const Rows& R, const Eigen::VectorXd& r) {
  double ss = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 1; i < R.n; ++i)
    if (R.run[i] == R.run[i - 1]) {
      const double d = r[static_cast<Eigen::Index>(i)] - r[static_cast<Eigen::Index>(i - 1)];
      ss += d * d;
      ++n;
    }
  return n ? std::sqrt(ss / (2.0 * static_cast<double>(n))) : 0.0;
}

NoiseModel noise_of(const Rows& R, const Eigen::VectorXd& r) {
  NoiseModelOptions o;
  o.pooled = true;
  o.pool_only_if_all_coloured = true;
  o.reml_random_walk = false;
  return estimate_noise_model(R.group, R.time, r, o);
}

// The model's columns for a list of chosen entries (spikes at their tau).
struct Chosen {
  CircularEffect effect;
  double tau = 0.0;                       // spike
  double delay = 0.0;                     // backlash, spike
  double delay_sd = 0.0;                  // its 1 sigma (after the scan)
  std::pair<double, double> delay_range = {0.0, 0.0};  // its delta-chi-square-1 range
};

Eigen::MatrixXd model_columns(const Rows& R, const Eigen::MatrixXd& B,
                              const std::vector<Chosen>& chosen, const Eigen::Vector3d& pitch,
                              std::vector<Eigen::Index>* offsets = nullptr) {
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

// GLS fit of y on M under whitening W: whitened residual sum of squares and coefficients.
struct Gls {
  Eigen::VectorXd beta, r_mm, r_w;
  double rss_w = 0.0;
};
// M = [B | E], B the baseline (whitened once per whitening: Whitening::baseline).
Gls gls(const Rows& R, const Eigen::MatrixXd& M, const Eigen::VectorXd& y, const Whitening& W) {
  Gls g;
  const Eigen::Index nb = static_cast<Eigen::Index>(3 * R.runs), ne = M.cols() - nb;
  const Whitening::Baseline& base = W.baseline(R, M.leftCols(nb));
  const Eigen::MatrixXd Ew = W(M.rightCols(ne));
  const Eigen::VectorXd yw = W(Eigen::MatrixXd(y)).col(0);
  g.beta = block_solve(R.run_first, R.run_count, base.Bw, base.qb, Ew, yw);
  g.r_w = yw - Ew * g.beta.tail(ne);
  for (std::size_t k = 0; k < R.runs; ++k) {
    const Eigen::Index c = static_cast<Eigen::Index>(3 * k);
    g.r_w.segment(R.run_first[k], R.run_count[k]) -=
        base.Bw.block(R.run_first[k], c, R.run_count[k], 3) * g.beta.segment(c, 3);
  }
  g.r_mm = y - M * g.beta;
  g.rss_w = g.r_w.squaredNorm();
  return g;
}

const std::vector<double> kSpikeTauGrid = {0.003, 0.006, 0.012, 0.025, 0.05, 0.1, 0.2};
const std::vector<double> kDelayGrid = {0.0, 0.0005, 0.001, 0.002, 0.004, 0.008, 0.016};

// Nonlinear parameters of an entry (they are profiled, not in the linear model).
int nonlinear_params(const CircularEffect& e) {
  if (e.kind == CircularEffectKind::backlash) return 1;
  if (e.kind == CircularEffectKind::reversal_spike) return 2;
  return 0;
}

// A candidate scored against the current model.
struct Scored {
  CircularEffect effect;
  double tau = 0.0, delay = 0.0;
  int k = 0;  // visible directions
  double rss1 = 0.0, delta_bic = 0.0, p = 1.0;
  bool visible = false;
  bool absorbed = false;  // visible on its own, not once the model is projected out
  bool physical = true;   // a spike sticks outward: h > 0
};

// Visibility, F and BIC of entry e against a model whose whitened residuals r_w leave rss0,
// from the entry's Gram quantities (k <= 2 columns, per unit parameter): G = perp' perp and
// g = perp' r_w, perp its whitened columns with the model projected out, and Graw = Jw' Jw
// without. Per plausible size (m) the singular values and right vectors of perp are the square
// roots and eigenvectors of m G m; the refit along the visible directions A = perp m V
// (orthogonal columns, squared norms the eigenvalues lambda) removes (v' m g)^2 / lambda each.
Scored score_gram(const CircularEffect& e, const Eigen::MatrixXd& G, const Eigen::VectorXd& g,
                  const Eigen::MatrixXd& Graw, double rss0, double n, int num_free,
                  double min_chi2) {
  Scored s;
  s.effect = e;
  const auto units = e.param_units();
  Eigen::VectorXd m(G.cols());
  for (Eigen::Index j = 0; j < G.cols(); ++j) m[j] = magnitude(units[static_cast<std::size_t>(j)]);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(m.asDiagonal() * G * m.asDiagonal());
  const double limit = std::sqrt(min_chi2);
  std::vector<Eigen::Index> dirs;
  for (Eigen::Index i = 0; i < eig.eigenvalues().size(); ++i)
    if (std::sqrt(std::max(eig.eigenvalues()[i], 0.0)) >= limit) dirs.push_back(i);
  if (dirs.empty()) {
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> er(m.asDiagonal() * Graw * m.asDiagonal(),
                                                            Eigen::EigenvaluesOnly);
    s.absorbed = er.eigenvalues().size() &&
                 std::sqrt(std::max(er.eigenvalues().maxCoeff(), 0.0)) >= limit;
    return s;
  }
  s.visible = true;
  s.k = static_cast<int>(dirs.size());
  const Eigen::VectorXd mg = m.cwiseProduct(g);
  Eigen::VectorXd d(s.k);
  Eigen::MatrixXd V(G.cols(), s.k);
  double explained = 0.0;
  for (int i = 0; i < s.k; ++i) {
    const Eigen::Index j = dirs[static_cast<std::size_t>(i)];
    V.col(i) = eig.eigenvectors().col(j);
    const double at_r = V.col(i).dot(mg);
    d[i] = at_r / eig.eigenvalues()[j];
    explained += at_r * d[i];
  }
  const Eigen::VectorXd params = m.cwiseProduct(V * d);  // in the entry's units
  if (e.kind == CircularEffectKind::reversal_spike) s.physical = params[0] > 0.0;
  s.rss1 = std::max(rss0 - explained, 1e-300);
  const int k_bic = s.k + nonlinear_params(e);
  s.delta_bic = n * std::log(s.rss1 / rss0) + k_bic * std::log(n);
  const double dof = n - num_free - k_bic;
  const double F = ((rss0 - s.rss1) / s.k) / (s.rss1 / dof);
  s.p = stats::f_sf(std::max(F, 0.0), s.k, dof);
  return s;
}

// score_gram of entry e (whitened columns Jw) against the model spanned by Q.
Scored score_one(const CircularEffect& e, const Eigen::MatrixXd& Jw, const ModelBasis& Q,
                 const Eigen::VectorXd& r_w, int num_free, double min_chi2) {
  const Eigen::MatrixXd perp = Q.project_out(Jw);
  return score_gram(e, perp.transpose() * perp, perp.transpose() * r_w, Jw.transpose() * Jw,
                    r_w.squaredNorm(), static_cast<double>(r_w.size()), num_free, min_chi2);
}

// The candidates of a forward selection with the noise taken as white (whitening = a scale
// s), where a round's model grows by one entry. Per variant only k x k and e x k numbers are
// kept, no column: the model's effect columns enter an orthonormal basis q one entry at a time
// (baseline projected out, Gram-Schmidt twice against q, a remainder below 1e-9 of the column
// dropped as in ModelBasis), each variant keeps c = q' s J, and since r_w and q are orthogonal to
// the baseline, perp' perp = gb - c' c and perp' r_w = s J' r_w - c' (q' r_w), with
// gb = (P s J)' (P s J) and P the baseline's projector. A round costs O(n k) per variant
// instead of a projection on the whole model.
class ScoringPool {
 public:
  ScoringPool(const Rows& R, const Whitening& W, const Eigen::MatrixXd& B,
              const std::vector<const Eigen::MatrixXd*>& variants)
      : R_(&R), W_(&W), scale_(W.scale), variants_(variants) {
    ROTACAL_ASSERT(!W.w);
    qb_ = W.baseline(R, B).qb;
    for (const Eigen::MatrixXd& q : qb_) rank_ += static_cast<int>(q.cols());
    q_.resize(static_cast<Eigen::Index>(R.n), 0);
    for (const Eigen::MatrixXd* J : variants) {
      Eigen::MatrixXd jb = scale_ * *J;
      graw_.push_back(jb.transpose() * jb);
      remove_baseline(qb_, R.run_first, R.run_count, jb);
      gb_.push_back(jb.transpose() * jb);
      c_.emplace_back(0, jb.cols());
    }
  }
  /// Add a chosen entry's (unwhitened) columns to the model.
  void add_to_model(const Eigen::MatrixXd& J) {
    Eigen::MatrixXd E = (*W_)(J);
    const Eigen::VectorXd norms = E.colwise().norm().transpose();
    remove_baseline(qb_, R_->run_first, R_->run_count, E);
    drop_absorbed(E, norms);
    for (Eigen::Index j = 0; j < E.cols(); ++j) {
      Eigen::VectorXd v = E.col(j);
      for (int pass = 0; pass < 2; ++pass)
        if (q_.cols() > 0) v -= q_ * (q_.transpose() * v);
      if (!(norms[j] > 0.0) || !(v.norm() > 1e-9 * norms[j])) continue;
      v.normalize();
      q_.conservativeResize(Eigen::NoChange, q_.cols() + 1);
      q_.col(q_.cols() - 1) = v;
      ++rank_;
      for (std::size_t i = 0; i < variants_.size(); ++i) {
        c_[i].conservativeResize(c_[i].rows() + 1, Eigen::NoChange);
        c_[i].row(c_[i].rows() - 1) = scale_ * (v.transpose() * *variants_[i]);
      }
    }
  }
  /// Dimension of the model's span (baseline and chosen entries).
  int rank() const { return rank_; }
  /// Variant i of entry e against the model, whose whitened residuals are r_w.
  Scored score(std::size_t i, const CircularEffect& e, const Eigen::VectorXd& r_w,
               double min_chi2) const {
    const Eigen::VectorXd qr = q_.transpose() * r_w;
    const Eigen::MatrixXd G = gb_[i] - c_[i].transpose() * c_[i];
    const Eigen::VectorXd g =
        scale_ * (variants_[i]->transpose() * r_w) - c_[i].transpose() * qr;
    return score_gram(e, G, g, graw_[i], r_w.squaredNorm(), static_cast<double>(r_w.size()),
                      rank_, min_chi2);
  }

 private:
  const Rows* R_;
  const Whitening* W_;
  double scale_;
  std::vector<const Eigen::MatrixXd*> variants_;
  std::vector<Eigen::MatrixXd> qb_;
  Eigen::MatrixXd q_;
  int rank_ = 0;
  std::vector<Eigen::MatrixXd> c_, gb_, graw_;
};

double rms_um(const Eigen::VectorXd& r) { return diagnosis_detail::rms_um(r); }

}  // namespace

CircularDiagnosis diagnose_circular(const BallbarSession& session,
                                    const CircularDiagnosisOptions& o) {
  if (!(o.alpha > 0.0 && o.alpha < 1.0))
    throw InvalidArgument("diagnose_circular: alpha must be in (0, 1), got " +
                          std::to_string(o.alpha));
  if (!o.screw_pitch.allFinite() || !(o.screw_pitch.array() > 0.0).all())
    throw InvalidArgument("diagnose_circular: screw_pitch must be positive (X, Y, Z), mm");
  if (o.max_findings < 0) throw InvalidArgument("diagnose_circular: max_findings must be >= 0");
  if (o.cv_blocks < 2) throw InvalidArgument("diagnose_circular: cv_blocks must be >= 2");
  std::vector<CircularEffect> catalogue;
  if (o.only.empty()) {
    catalogue = circular_catalogue();
  } else {
    for (const std::string& id : o.only) catalogue.push_back(CircularEffect::parse(id));
  }

  const std::vector<CircularRunData> runs = circular_runs(session);
  const Rows R = gather(session, runs);
  const Eigen::MatrixXd B = baseline_columns(R);
  CircularDiagnosis out;
  out.n = R.n;

  // Entries these runs cannot see at all; the axes' own scales, never.
  std::vector<CircularEffect> cands;
  for (const CircularEffect& e : catalogue) {
    const std::string why = not_moved(R, e);
    if (why.empty())
      cands.push_back(e);
    else
      out.unobservable.push_back({e.id(), why});
  }
  for (int a = 0; a < 3; ++a)
    out.unobservable.push_back(
        {"scale_" + axis_name(a),
         "a circle sees only the difference of its two axes' scales (scale_mismatch_*); their "
         "common "
         "part changes the radius, which cannot be told from the bar length's calibration"});

  // Candidate columns, computed once: backlash over the delay grid, spikes over tau x delay.
  struct Variant {
    double tau = 0.0, delay = 0.0;
    Eigen::MatrixXd J;
  };
  std::map<std::string, std::vector<Variant>> cols;
  for (const CircularEffect& e : cands) {
    if (e.kind == CircularEffectKind::reversal_spike) {
      for (double tau : kSpikeTauGrid)
        for (double delay : kDelayGrid)
          cols[e.id()].push_back({tau, delay, effect_columns(R, e, o.screw_pitch, tau, delay)});
    } else if (e.kind == CircularEffectKind::backlash) {
      for (double delay : kDelayGrid)
        cols[e.id()].push_back({0.0, delay, effect_columns(R, e, o.screw_pitch, 0.0, delay)});
    } else {
      cols[e.id()].push_back({0.0, 0.0, effect_columns(R, e, o.screw_pitch)});
    }
  }

  std::vector<Chosen> chosen;
  Whitening W;
  Gls fit = gls(R, B, R.y, W);  // ordinary least squares first
  out.baseline_rms_um = rms_um(fit.r_mm);
  std::set<std::string> absorbed;   // ids absorbed by the model at the last round
  std::set<std::string> invisible;  // ids too small to see at plausible sizes
  const auto refit_noise = [&]() {
    if (!o.model_noise) return;
    NoiseModel nm = noise_of(R, fit.r_mm);
    W.set(nm);
    fit = gls(R, model_columns(R, B, chosen, o.screw_pitch), R.y, W);
  };
  const auto is_chosen = [&](const std::string& id) {
    return std::any_of(chosen.begin(), chosen.end(),
                       [&](const Chosen& c) { return c.effect.id() == id; });
  };
  // Forward selection under the current whitening; `ar`: re-estimate the noise every round.
  // Every variant's columns, in the order of cands (a pool's variant index).
  std::vector<const Eigen::MatrixXd*> variant_columns;
  for (const CircularEffect& e : cands)
    for (const auto& v : cols[e.id()]) variant_columns.push_back(&v.J);
  // Forward selection; under white noise (a whitening that stays for every round) through a
  // ScoringPool, under the AR model (re-estimated every round) by projecting each variant.
  const auto forward = [&](bool ar, int limit, bool record) {
    std::unique_ptr<ScoringPool> pool;
    for (int round = 0;; ++round) {
      if (ar) refit_noise();
      std::unique_ptr<ModelBasis> Q;
      if (W.w) {
        Q = std::make_unique<ModelBasis>(R, W(model_columns(R, B, chosen, o.screw_pitch)));
      } else if (!pool) {
        pool = std::make_unique<ScoringPool>(R, W, B, variant_columns);
        for (const Chosen& c : chosen)
          pool->add_to_model(effect_columns(R, c.effect, o.screw_pitch, c.tau, c.delay));
      }
      const auto score_variant = [&](std::size_t i, const CircularEffect& e) {
        return Q ? score_one(e, W(*variant_columns[i]), *Q, fit.r_w, Q->rank(), o.min_visible_chi2)
                 : pool->score(i, e, fit.r_w, o.min_visible_chi2);
      };
      std::vector<Scored> scores;
      absorbed.clear();
      invisible.clear();
      std::size_t variant_index = 0;
      for (const CircularEffect& e : cands) {
        const auto& cs = cols[e.id()];
        const std::size_t first_variant = variant_index;
        variant_index += cs.size();
        if (is_chosen(e.id())) continue;
        Scored best;
        bool have = false;
        for (std::size_t g = 0; g < cs.size(); ++g) {
          Scored sc = score_variant(first_variant + g, e);
          sc.tau = cs[g].tau;
          sc.delay = cs[g].delay;
          if (!have || (sc.visible && (!best.visible || sc.rss1 < best.rss1)))
            best = sc, have = true;
        }
        if (!best.visible) {
          (best.absorbed ? absorbed : invisible).insert(e.id());
          continue;
        }
        scores.push_back(best);
      }
      std::sort(scores.begin(), scores.end(),
                [](const Scored& x, const Scored& y) { return x.delta_bic < y.delta_bic; });
      if (record && round == 0)
        for (const Scored& sc : scores)
          out.first_round.push_back({sc.effect.id(), sc.k, sc.delta_bic, sc.p,
                                     std::sqrt(sc.rss1 / static_cast<double>(R.n))});
      if (static_cast<int>(chosen.size()) >= limit) return;
      const double m = static_cast<double>(std::max<std::size_t>(scores.size(), 1));
      const Scored* pick = nullptr;
      for (const Scored& sc : scores)
        if (sc.p * m < o.alpha && sc.delta_bic < o.min_delta_bic && sc.physical) {
          pick = &sc;
          break;
        }
      if (!pick) return;
      chosen.push_back({pick->effect, pick->tau, pick->delay});
      fit = gls(R, model_columns(R, B, chosen, o.screw_pitch), R.y, W);
      if (pool)
        pool->add_to_model(effect_columns(R, pick->effect, o.screw_pitch, pick->tau, pick->delay));
    }
  };
  // Backward elimination under the current noise model: drop the entry whose drop-one test
  // fails worst (Bonferroni over the catalogue; a spike that does not stick outward fails),
  // refit and re-estimate the noise, until every entry left passes.
  const auto eliminate = [&]() {
    const double m = static_cast<double>(std::max<std::size_t>(cands.size(), 1));
    while (!chosen.empty()) {
      const double n = static_cast<double>(R.n);
      std::vector<Eigen::Index> offs;
      const Eigen::MatrixXd Mk = model_columns(R, B, chosen, o.screw_pitch, &offs);
      std::size_t worst = chosen.size();
      double worst_score = -1.0;
      // Every drop-one refit from one QR of the whitened model (CompressedFit).
      const CompressedFit drop(R, W(Mk), W(Eigen::MatrixXd(R.y)).col(0));
      for (std::size_t k = 0; k < chosen.size(); ++k) {
        const Eigen::Index width =
            (k + 1 < chosen.size() ? offs[k + 1] : Mk.cols()) - offs[k];
        const double rss_without = drop.rss_without(offs[k], width);
        const int kk = static_cast<int>(width) + nonlinear_params(chosen[k].effect);
        const double dof = n - static_cast<double>(Mk.cols()) - 1.0;
        const double F = ((rss_without - fit.rss_w) / kk) / (fit.rss_w / dof);
        const double p = stats::f_sf(std::max(F, 0.0), kk, dof);
        const double dbic =
            n * std::log(std::max(fit.rss_w, 1e-300) / rss_without) + kk * std::log(n);
        const bool outward =
            chosen[k].effect.kind != CircularEffectKind::reversal_spike || fit.beta[offs[k]] > 0.0;
        const double score =
            (p * m < o.alpha && dbic < o.min_delta_bic && outward)
                ? -1.0
                : p + (dbic >= o.min_delta_bic ? 1.0 : 0.0) + (outward ? 0.0 : 2.0);
        if (score > worst_score) worst_score = score, worst = k;
      }
      if (worst_score < 0.0) break;
      chosen.erase(chosen.begin() + static_cast<std::ptrdiff_t>(worst));
      fit = gls(R, model_columns(R, B, chosen, o.screw_pitch), R.y, W);
      refit_noise();
    }
  };
  // 1. Forward with the noise taken as white, sigma from successive differences: the residuals
  //    of the baseline hold the large signatures, and an AR model fitted to them would take
  //    those for noise and whiten them away. White-noise tests are too lenient on coloured
  //    noise; step 2 corrects that.
  {
    const double sd = difference_sigma(R, fit.r_mm);
    W.set_scale(sd > 0.0 ? 1.0 / sd : 1.0);
    fit = gls(R, B, R.y, W);
  }
  forward(false, o.max_findings + 6, true);
  if (o.model_noise) {
    // 2. Noise modelled from what the model leaves; backward elimination of every entry whose
    //    drop-one test fails under it (Bonferroni over the catalogue), the noise re-estimated
    //    after each removal.
    refit_noise();
    eliminate();
    // 3. Forward again under the AR model, re-estimated every round.
    forward(true, o.max_findings, false);
  }

  // Nonlinear parameters (a spike's ln tau, a reversal delay): golden section about the grid
  // value, every linear parameter refitted at each trial (a profile), two sweeps.
  const auto rss_with = [&](Chosen& c, double* field, double value) {
    const double keep = *field;
    *field = value;
    const double v = gls(R, model_columns(R, B, chosen, o.screw_pitch), R.y, W).rss_w;
    *field = keep;
    return v;
  };
  const auto golden = [](const std::function<double(double)>& f, double a, double b) {
    const double g = 0.5 * (std::sqrt(5.0) - 1.0);
    double x1 = b - g * (b - a), x2 = a + g * (b - a), f1 = f(x1), f2 = f(x2);
    for (int it = 0; it < 30 && b - a > 1e-6 * (1.0 + std::abs(a)); ++it) {
      if (f1 <= f2) {
        b = x2, x2 = x1, f2 = f1, x1 = b - g * (b - a), f1 = f(x1);
      } else {
        a = x1, x1 = x2, f1 = f2, x2 = a + g * (b - a), f2 = f(x2);
      }
    }
    return 0.5 * (a + b);
  };
  // A reversal delay moves a step in time: the model changes only when a step crosses a
  // reading, so the profile is a staircase. Scan it (0..20 ms by 0.5 ms, then +-0.5 ms by
  // 0.05 ms) and take the middle of the lowest stair; its width is the resolution.
  // The profile of entry k's nonlinear parameters with the rest of the model fixed in
  // structure: whitened residual of y on the other columns, then the entry's columns projected
  // on what is left (Frisch-Waugh), O(n p) per trial instead of a full refit.
  const auto profile_of = [&](std::size_t k) {
    std::vector<Chosen> others = chosen;
    others.erase(others.begin() + static_cast<std::ptrdiff_t>(k));
    const ModelBasis Q(R, W(model_columns(R, B, others, o.screw_pitch)));
    const Eigen::VectorXd r0 = Q.project_out(W(Eigen::MatrixXd(R.y))).col(0);
    const CircularEffect e = chosen[k].effect;
    // A trial whose columns equal the previous trial's (a delay step that crosses no reading)
    // has its value: the same computation on the same numbers.
    auto last = std::make_shared<std::pair<Eigen::MatrixXd, double>>();
    return [&, Q, r0, e, last](double tau, double delay) {
      Eigen::MatrixXd J = effect_columns(R, e, o.screw_pitch, tau, delay);
      if (last->first.size() == J.size() && last->first == J) return last->second;
      const Eigen::MatrixXd A = Q.project_out(W(J));
      const Eigen::VectorXd d = solve_ls(A, r0);
      *last = {std::move(J), (r0 - A * d).squaredNorm()};
      return last->second;
    };
  };
  const auto scan_delay = [&](std::size_t k, const std::function<double(double, double)>& f) {
    Chosen& c = chosen[k];
    double best = c.delay, fbest = f(c.tau, c.delay);
    for (double x = 0.0; x <= 0.020 + 1e-12; x += 0.0005) {
      const double v = f(c.tau, x);
      if (v < fbest) fbest = v, best = x;
    }
    std::vector<double> xs, fs;
    for (double x = std::max(0.0, best - 0.002); x <= best + 0.002 + 1e-12; x += 0.00005) {
      xs.push_back(x);
      fs.push_back(f(c.tau, x));
    }
    const double fmin = *std::min_element(fs.begin(), fs.end());
    std::size_t i0 = 0;
    while (fs[i0] > fmin * (1.0 + 1e-12)) ++i0;
    std::size_t i1 = i0;
    while (i1 + 1 < fs.size() && fs[i1 + 1] <= fmin * (1.0 + 1e-12)) ++i1;
    c.delay = 0.5 * (xs[i0] + xs[i1]);
    // 1 sigma: half the range where the profile stays within delta chi-square 1 of its minimum
    // (whitened residuals have unit variance: s2 = fmin / dof), at least the stair's own
    // uniform spread.
    const double s2p = fmin / static_cast<double>(R.n);
    std::size_t j0 = i0, j1 = i1;
    while (j0 > 0 && fs[j0 - 1] <= fmin + s2p) --j0;
    while (j1 + 1 < fs.size() && fs[j1 + 1] <= fmin + s2p) ++j1;
    c.delay_range = {xs[j0], xs[j1]};
    c.delay_sd =
        std::max(std::max(xs[i1] - xs[i0], 0.00005) / std::sqrt(12.0), 0.5 * (xs[j1] - xs[j0]));
  };
  for (int sweep = 0; sweep < 2; ++sweep)
    for (std::size_t k = 0; k < chosen.size(); ++k) {
      Chosen& c = chosen[k];
      if (!nonlinear_params(c.effect)) continue;
      const std::function<double(double, double)> f = profile_of(k);
      if (c.effect.kind == CircularEffectKind::reversal_spike)
        c.tau = std::exp(golden([&](double x) { return f(std::exp(x), c.delay); },
                                std::log(c.tau) - 0.7, std::log(c.tau) + 0.7));
      scan_delay(k, f);
    }

  // What the refinement moved may no longer pass (or a spike may no longer stick outward).
  if (o.model_noise) {
    fit = gls(R, model_columns(R, B, chosen, o.screw_pitch), R.y, W);
    refit_noise();
    eliminate();
  }

  // Final model: noise from its residuals, GLS; linear parameters' 1-sigma from the whitened
  // Jacobian, the nonlinear ones' from the curvature of the profile (delta chi-square 1).
  std::vector<Eigen::Index> offsets;
  Eigen::MatrixXd M = model_columns(R, B, chosen, o.screw_pitch, &offsets);
  fit = gls(R, M, R.y, W);
  if (o.model_noise) {
    out.noise = noise_of(R, fit.r_mm);
    W.set(out.noise);
    fit = gls(R, M, R.y, W);
  } else {
    out.noise = noise_of(R, fit.r_mm);
  }
  out.noise_whitened = W.w != nullptr;
  out.residuals_mm = fit.r_mm;
  out.final_rms_um = rms_um(fit.r_mm);
  const Eigen::MatrixXd& Jfull = M;
  const Eigen::MatrixXd Jw = W(Jfull);
  int n_nonlinear = 0;
  for (const Chosen& c : chosen) n_nonlinear += nonlinear_params(c.effect);
  const double dof = static_cast<double>(R.n) - static_cast<double>(Jw.cols()) - n_nonlinear;
  const double s2 = fit.rss_w / dof;
  // Column-scaled inverse of the normal matrix: the baseline's columns are O(1), the effects'
  // up to O(R^2); scaling keeps the inverse accurate.
  Eigen::VectorXd sc = Jw.colwise().norm().transpose();
  for (Eigen::Index j = 0; j < sc.size(); ++j)
    if (!(sc[j] > 0.0)) sc[j] = 1.0;
  const Eigen::MatrixXd Js = Jw * sc.cwiseInverse().asDiagonal();
  const Eigen::MatrixXd Ninv =
      (Js.transpose() * Js).ldlt().solve(Eigen::MatrixXd::Identity(Js.cols(), Js.cols()));
  const auto std_of = [&](Eigen::Index j) {
    return std::sqrt(std::max(Ninv(j, j), 0.0) * s2) / sc[j];
  };
  // 1-sigma of a profiled parameter: rss_w(x) ~ rss_w(x0) + f'' (x - x0)^2 / 2, chi-square
  // rss_w / s2, so sigma = sqrt(2 s2 / f''); not determined (observable false) if f'' <= 0.
  const auto profile_std = [&](Chosen& c, double* field, double h,
                               bool log_scale) -> std::pair<double, bool> {
    const double x0 = *field;
    const auto at = [&](double x) { return rss_with(c, field, log_scale ? std::exp(x) : x); };
    const double c0 = log_scale ? std::log(x0) : x0;
    const double lo = log_scale ? c0 - h : std::max(0.0, c0 - h), hi = lo + 2.0 * h;
    const double mid = 0.5 * (lo + hi);
    const double f2 = (at(hi) - 2.0 * at(mid) + at(lo)) / (h * h);
    if (!(f2 > 0.0)) return {std::numeric_limits<double>::quiet_NaN(), false};
    const double sd = std::sqrt(2.0 * s2 / f2);
    return {log_scale ? sd * x0 : sd, true};
  };

  const std::vector<int> fold = [&] {
    std::vector<int> f(R.n);
    std::map<int, std::pair<std::size_t, std::size_t>> span;  // run -> first row, count
    for (std::size_t i = 0; i < R.n; ++i) {
      auto it = span.find(R.run[i]);
      if (it == span.end())
        span[R.run[i]] = {i, 1};
      else
        ++it->second.second;
    }
    for (std::size_t i = 0; i < R.n; ++i) {
      const auto& sp = span[R.run[i]];
      f[i] = static_cast<int>((i - sp.first) * static_cast<std::size_t>(o.cv_blocks) / sp.second);
    }
    return f;
  }();
  const double cv_all = cv_rms_um(R, M, R.y, fold, o.cv_blocks);
  // The nonlinear parameters' uncertainty moves the linear ones (a spike's height trades with
  // its delay and tau): each linear parameter's variance gets the square of its half change
  // across the nonlinear parameter's range (tau: +-1 sigma), refitted.
  std::vector<std::pair<double, bool>> tau_sd(chosen.size(), {0.0, false});
  Eigen::VectorXd extra_var = Eigen::VectorXd::Zero(M.cols());
  const auto beta_at = [&](std::size_t k, double tau, double delay) {
    const Chosen keep = chosen[k];
    chosen[k].tau = tau;
    chosen[k].delay = delay;
    const Eigen::VectorXd b = gls(R, model_columns(R, B, chosen, o.screw_pitch), R.y, W).beta;
    chosen[k] = keep;
    return b;
  };
  for (std::size_t k = 0; k < chosen.size(); ++k) {
    const Chosen c = chosen[k];
    if (c.effect.kind == CircularEffectKind::reversal_spike) {
      tau_sd[k] = profile_std(chosen[k], &chosen[k].tau, 0.05, true);
      if (tau_sd[k].second && tau_sd[k].first < c.tau) {
        const Eigen::VectorXd d = 0.5 * (beta_at(k, c.tau + tau_sd[k].first, c.delay) -
                                         beta_at(k, c.tau - tau_sd[k].first, c.delay));
        extra_var += d.cwiseAbs2();
      }
    }
    // A delay: between the ends of its delta-chi-square-1 range (readings inside it; the model
    // jumps where a step crosses a reading, so +-1 sigma could land beyond a stair's edge).
    if (nonlinear_params(c.effect) && c.delay_range.second > c.delay_range.first) {
      const Eigen::VectorXd d =
          0.5 * (beta_at(k, c.tau, c.delay_range.second) - beta_at(k, c.tau, c.delay_range.first));
      extra_var += d.cwiseAbs2();
    }
  }
  for (std::size_t k = 0; k < chosen.size(); ++k) {
    CircularFinding f;
    f.effect = chosen[k].effect.id();
    f.cause = chosen[k].effect.cause();
    const auto names = chosen[k].effect.param_names();
    const auto units = chosen[k].effect.param_units();
    for (std::size_t j = 0; j < names.size(); ++j) {
      ParameterEstimate p;
      p.name = f.effect + "." + names[j];
      p.unit = units[j];
      if (names[j] == "tau") {
        p.value = chosen[k].tau;
        p.std = tau_sd[k].first;
        p.observable = tau_sd[k].second;
      } else if (names[j] == "delay") {
        p.value = chosen[k].delay;
        p.std = chosen[k].delay_sd;
      } else {
        const Eigen::Index c = offsets[k] + static_cast<Eigen::Index>(j);
        p.value = fit.beta[c];
        p.std = std::sqrt(std_of(c) * std_of(c) + extra_var[c]);
      }
      f.parameters.push_back(p);
    }
    // Gain: the final model without this entry, refitted under the same noise model.
    std::vector<Chosen> others = chosen;
    others.erase(others.begin() + static_cast<std::ptrdiff_t>(k));
    const Eigen::MatrixXd Mo = model_columns(R, B, others, o.screw_pitch);
    const Gls without = gls(R, Mo, R.y, W);
    const double n = static_cast<double>(R.n);
    const int kk = static_cast<int>(M.cols() - Mo.cols()) + nonlinear_params(chosen[k].effect);
    f.gain.rms_before_um = rms_um(without.r_mm);
    f.gain.rms_after_um = out.final_rms_um;
    f.gain.delta_bic = n * std::log(std::max(fit.rss_w, 1e-300) / without.rss_w) + kk * std::log(n);
    const double F = ((without.rss_w - fit.rss_w) / kk) / (fit.rss_w / dof);
    f.gain.f_pvalue = stats::f_sf(std::max(F, 0.0), kk, dof);
    f.gain.cv_rms_before_um = cv_rms_um(R, Mo, R.y, fold, o.cv_blocks);
    f.gain.cv_rms_after_um = cv_all;
    out.findings.push_back(std::move(f));
  }

  for (const std::string& id : invisible)
    out.unobservable.push_back(
        {id, "at plausible sizes it changes these readings by less than 5 sigma in all"});
  // Entries left out that the final model makes invisible: name what absorbs them.
  const ModelBasis Qb(R, W(B));
  for (const CircularEffect& e : cands) {
    if (!absorbed.count(e.id())) continue;
    const Eigen::MatrixXd Jc = W(cols[e.id()].front().J);
    Scored vs_base = score_one(e, Jc, Qb, Eigen::VectorXd::Zero(Jc.rows()), Qb.rank(),
                               o.min_visible_chi2);
    std::string why;
    if (!vs_base.visible) {
      why = "the centre offset and radius of each run absorb its signature in these runs";
    } else {
      std::string by;
      for (const Chosen& c : chosen) {
        std::vector<Chosen> one = {c};
        const ModelBasis Q1(R, W(model_columns(R, B, one, o.screw_pitch)));
        if (!score_one(e, Jc, Q1, Eigen::VectorXd::Zero(Jc.rows()), Q1.rank(), o.min_visible_chi2)
                 .visible)
          by += (by.empty() ? "" : ", ") + c.effect.id();
      }
      why = "in these runs its signature is that of " +
            (by.empty() ? std::string("the findings together") : by);
      const bool sq_servo = (e.kind == CircularEffectKind::squareness ||
                             e.kind == CircularEffectKind::servo_mismatch);
      if (sq_servo && (R.directions.size() < 2))
        why += ": a cw and a ccw run (or two feeds) separate squareness from servo mismatch";
    }
    out.unobservable.push_back({e.id(), why});
  }
  return out;
}

}  // namespace rotacal

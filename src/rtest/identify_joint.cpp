#include "rotacal/rtest/identify_joint.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "rotacal/core/least_squares.hpp"

namespace rotacal {

namespace {
const char* kCompNames[6] = {"dx", "dy", "dz", "alpha", "beta", "gamma"};
}

// ---------------------------------------------------------------- basis
int RtestBasis::num_b_coefficients() const {
  int n = 0;
  for (int k = 0; k < 6; ++k) n += static_cast<int>(b_terms(k, 0.3).size());
  return n;
}
int RtestBasis::num_c_coefficients() const {
  return static_cast<int>(coefficient_names().size()) - num_b_coefficients();
}
namespace {
// The C-map terms: (component k, harmonic n, cos/sin, power m), except that for the pairs
// (dx, dy) and (alpha, beta) at n = 1, m = 0 only the backward-turning motion
// (u cos C + v sin C, -u sin C + v cos C) is kept (see the header). Calls f(name, term).
template <typename F>
void for_each_c_term(const RtestBasis& bs, double B, double C, F f) {
  const double b = B / (M_PI / 2.0);
  for (int k = 0; k < (bs.gamma_cb ? 6 : 5); ++k)
    for (int n = 1; n <= bs.c_harmonics; ++n) {
      double bm = 1.0;
      for (int m = 0; m <= bs.c_b_degree; ++m, bm *= b)
        for (int cs = 0; cs < 2; ++cs) {
          AxisErrors<double> t = AxisErrors<double>::Zero();
          const bool pair = k == 0 || k == 1 || k == 3 || k == 4;
          if (pair && n == 1 && m == 0) {
            if (k == 1 || k == 4) continue;  // carried by the pair's first component
            const double c = std::cos(C), s = std::sin(C);
            t[k] = cs == 0 ? c : s;
            t[k + 1] = cs == 0 ? -s : c;
            f(std::string(k == 0 ? "dxy" : "alphabeta") + "_CB.back1." + (cs == 0 ? "u" : "v") + ".b0",
              t);
            continue;
          }
          t[k] = bm * (cs == 0 ? std::cos(n * C) : std::sin(n * C));
          f(std::string(kCompNames[k]) + "_CB." + (cs == 0 ? "cos" : "sin") + std::to_string(n) +
                ".b" + std::to_string(m),
            t);
        }
    }
}
}  // namespace
std::vector<AxisErrors<double>> RtestBasis::c_terms(double B, double C) const {
  std::vector<AxisErrors<double>> out;
  for_each_c_term(*this, B, C, [&](const std::string&, const AxisErrors<double>& t) { out.push_back(t); });
  return out;
}
std::vector<double> RtestBasis::b_terms(int k, double B) const {
  const double b = B / (M_PI / 2.0);
  std::vector<double> out;
  for (int p = (k < 3 ? 2 : 1); p <= b_degree; p += 2) out.push_back(std::pow(b, p));
  return out;
}
std::vector<std::string> RtestBasis::coefficient_names() const {
  std::vector<std::string> out;
  for (int k = 0; k < 6; ++k)
    for (int p = (k < 3 ? 2 : 1); p <= b_degree; p += 2)
      out.push_back(std::string(kCompNames[k]) + "_BY.b" + std::to_string(p));
  for_each_c_term(*this, 0.3, 0.7,
                  [&](const std::string& n, const AxisErrors<double>&) { out.push_back(n); });
  return out;
}

// ---------------------------------------------------------------- model
LocationErrors<double> RtestJointModel::errors() const {
  return LocationErrors<double>(params.head<8>());
}

namespace {
// Linear map from params to w_BY (6 x P) and w_CB (6 x P) at (B, C).
void map_rows(const RtestJointModel& m, double B, double C, Eigen::MatrixXd& Lb,
              Eigen::MatrixXd& Lc) {
  const int P = static_cast<int>(m.params.size());
  const int nb = m.basis.num_b_coefficients();
  Lb = Eigen::MatrixXd::Zero(6, P);
  Lc = Eigen::MatrixXd::Zero(6, P);
  int o = 8;
  for (int k = 0; k < 6; ++k)
    for (double phi : m.basis.b_terms(k, B)) Lb(k, o++) = phi;
  o = 8 + nb;
  for (const AxisErrors<double>& t : m.basis.c_terms(B, C)) Lc.col(o++) = t;
}

AxisErrors<double> propagate(const RtestJointModel& m, const Eigen::MatrixXd& L) {
  AxisErrors<double> s;
  for (int k = 0; k < 6; ++k) {
    bool ok = true;
    for (Eigen::Index j = 0; j < L.cols(); ++j)
      if (L(k, j) != 0.0 && !m.observable[static_cast<std::size_t>(j)]) ok = false;
    s[k] = ok ? std::sqrt(std::max(0.0, double(L.row(k) * m.covariance * L.row(k).transpose())))
              : std::numeric_limits<double>::quiet_NaN();
  }
  return s;
}

// 1-sigma of a function of the params by central differences (the model is linear to well
// below the noise over the identified magnitudes).
template <typename F>
Eigen::Vector3d propagate_fn(const RtestJointModel& m, F f) {
  const int P = static_cast<int>(m.params.size());
  Eigen::MatrixXd J(3, P);
  RtestJointModel t = m;
  for (int j = 0; j < P; ++j) {
    const double h = location_error_is_angle(j) && j < 8 ? 1e-7 : 1e-5;
    t.params = m.params;
    t.params[j] += h;
    const Eigen::Vector3d fp = f(t);
    t.params[j] -= 2 * h;
    J.col(j) = (fp - f(t)) / (2 * h);
  }
  Eigen::Vector3d s;
  for (int r = 0; r < 3; ++r) {
    bool ok = true;
    for (int j = 0; j < P; ++j)
      if (std::abs(J(r, j)) > 1e-9 && !m.observable[static_cast<std::size_t>(j)]) ok = false;
    s[r] = ok ? std::sqrt(std::max(0.0, double(J.row(r) * m.covariance * J.row(r).transpose())))
              : std::numeric_limits<double>::quiet_NaN();
  }
  return s;
}
}  // namespace

AxisErrors<double> RtestJointModel::w_BY(double B, AxisErrors<double>* std) const {
  Eigen::MatrixXd Lb, Lc;
  map_rows(*this, B, 0.0, Lb, Lc);
  if (std) *std = propagate(*this, Lb);
  return Lb * params;
}
AxisErrors<double> RtestJointModel::w_CB(double B, double C, AxisErrors<double>* std) const {
  Eigen::MatrixXd Lb, Lc;
  map_rows(*this, B, C, Lb, Lc);
  if (std) *std = propagate(*this, Lc);
  return Lc * params;
}
Pose<double> RtestJointModel::table_pose(double B, double C) const {
  const int nb = basis.num_b_coefficients();
  return rtest_joint_table_pose<double>(basis, params.data(), params.data() + 8,
                                        params.data() + 8 + nb, B, C);
}
Eigen::Vector3d RtestJointModel::reading(const Eigen::Vector3d& q, double B, double C,
                                         Eigen::Vector3d* std) const {
  auto f = [&](const RtestJointModel& m) {
    const Eigen::Vector3d xyz = forward<double>(MachineType::BC_trt, LocationErrors<double>(), {B, C}, q);
    return Eigen::Vector3d(m.table_pose(B, C).inverse() * xyz - q);
  };
  if (std) *std = propagate_fn(*this, f);
  return f(*this);
}
Eigen::Vector3d RtestJointModel::table_error(const Eigen::Vector3d& q, double B, double C,
                                             Eigen::Vector3d* std) const {
  auto f = [&](const RtestJointModel& m) {
    return Eigen::Vector3d(m.table_pose(B, C) * q -
                           forward<double>(MachineType::BC_trt, LocationErrors<double>(), {B, C}, q));
  };
  if (std) *std = propagate_fn(*this, f);
  return f(*this);
}

const ParameterEstimate& RtestJointIdentification::parameter(const std::string& name) const {
  for (const ParameterEstimate& p : parameters)
    if (p.name == name) return p;
  throw InvalidArgument("no identified parameter named '" + name + "'");
}

// ---------------------------------------------------------------- fit
namespace {
// r = (T^-1 xyz - q + zero - d_measured) / sigma, 3 residuals per sample (Eq. 4 with location
// errors and the smooth maps). Blocks: location errors (8), B coefficients, C coefficients
// (each at least 1 long; held constant when the basis is empty), probe zero (3).
struct RtestReadingResidual {
  RtestReadingResidual(const RtestBasis& basis, const RtestSample& s, const Eigen::Vector3d& q,
                       double inv_sigma)
      : basis_(basis), B_(s.angles_rad().tilt), C_(s.angles_rad().rot), xyz_(s.xyz), q_(q),
        d_(*s.d), inv_sigma_(inv_sigma) {}

  template <typename T>
  bool operator()(T const* const* p, T* r) const {
    const Pose<T> P = rtest_joint_table_pose<T>(basis_, p[0], p[1], p[2], B_, C_);
    const Vec3<T> d = P.inverse() * xyz_.cast<T>() - q_.cast<T>();
    for (int i = 0; i < 3; ++i) r[i] = (d[i] + p[3][i] - T(d_[i])) * T(inv_sigma_);
    return true;
  }

  static ceres::CostFunction* Create(const RtestBasis& basis, const RtestSample& s,
                                     const Eigen::Vector3d& q, double inv_sigma, int nb, int nc) {
    auto* cost = new ceres::DynamicAutoDiffCostFunction<RtestReadingResidual, 16>(
        new RtestReadingResidual(basis, s, q, inv_sigma));
    cost->AddParameterBlock(8);
    cost->AddParameterBlock(nb);
    cost->AddParameterBlock(nc);
    cost->AddParameterBlock(3);
    cost->SetNumResiduals(3);
    return cost;
  }

 private:
  RtestBasis basis_;
  double B_, C_;
  Eigen::Vector3d xyz_, q_, d_;
  double inv_sigma_;
};
}  // namespace

RtestJointIdentification identify_joint(const RtestSession& session,
                                        const RtestJointOptions& options) {
  if (session.machine != MachineType::BC_trt)
    throw InvalidArgument("identify_joint: session.machine: the R-test model is for BC-trt tables");
  const RtestBasis& basis = options.basis;
  if (basis.b_degree < 0 || basis.c_harmonics < 0 || basis.c_b_degree < 0)
    throw InvalidArgument("identify_joint: options.basis: degrees and harmonics must be >= 0");
  const std::vector<std::string> setups = session.setups();
  for (std::size_t i = 0; i < session.samples.size(); ++i) {
    if (!session.samples[i].d)
      throw InvalidArgument("identify_joint: session: sample " + std::to_string(i) +
                            " has no dx,dy,dz (convert raw readings with displacements_from_raw)");
    if (!session.nests.count(session.samples[i].setup))
      throw InvalidArgument("identify_joint: session.nests: no nest." + session.samples[i].setup);
  }
  const int nb = basis.num_b_coefficients(), nc = basis.num_c_coefficients();
  const int n_model = 8 + nb + nc;
  const int n_par = n_model + 3 * static_cast<int>(setups.size());
  if (3 * static_cast<int>(session.samples.size()) <= n_par)
    throw InvalidArgument("identify_joint: session: " + std::to_string(3 * session.samples.size()) +
                          " readings cannot determine " + std::to_string(n_par) + " unknowns");

  const double sigma_mm = session.noise_um.value_or(1.0) * 1e-3;  // scales the cost only
  Eigen::Matrix<double, 8, 1> e = Eigen::Matrix<double, 8, 1>::Zero();
  std::vector<double> cb(static_cast<std::size_t>(std::max(nb, 1)), 0.0);
  std::vector<double> cc(static_cast<std::size_t>(std::max(nc, 1)), 0.0);
  // Start each probe zero at its set-up's mean reading (the closed-form answer for zero errors).
  std::vector<Eigen::Vector3d> zeros(setups.size(), Eigen::Vector3d::Zero());
  for (std::size_t k = 0; k < setups.size(); ++k) {
    const auto idx = session.indices_of(setups[k]);
    for (std::size_t i : idx) zeros[k] += *session.samples[i].d;
    zeros[k] /= static_cast<double>(idx.size());
  }

  ceres::Problem::Options po;
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;  // evaluate_jacobian detaches them
  ceres::Problem problem(po);
  std::vector<std::unique_ptr<ceres::Manifold>> manifolds;
  for (const RtestSample& s : session.samples) {
    const std::size_t k = static_cast<std::size_t>(
        std::find(setups.begin(), setups.end(), s.setup) - setups.begin());
    problem.AddResidualBlock(
        RtestReadingResidual::Create(basis, s, session.nests.at(s.setup), 1.0 / sigma_mm,
                                     static_cast<int>(cb.size()), static_cast<int>(cc.size())),
        nullptr, {e.data(), cb.data(), cc.data(), zeros[k].data()});
  }
  if (nb == 0) problem.SetParameterBlockConstant(cb.data());
  if (nc == 0) problem.SetParameterBlockConstant(cc.data());

  std::vector<std::string> names, units;
  for (int k = 0; k < 8; ++k) {
    names.push_back(location_error_names(MachineType::BC_trt)[static_cast<std::size_t>(k)]);
    units.push_back(location_error_is_angle(k) ? "rad" : "mm");
  }
  for (const std::string& n : basis.coefficient_names()) {
    names.push_back(n);
    const std::string comp = n.substr(0, n.find('_'));
    units.push_back(comp[0] == 'd' ? "mm" : "rad");
  }
  for (const std::string& s : setups)
    for (const char* c : {"x", "y", "z"}) names.push_back("zero." + s + "." + c), units.push_back("mm");

  std::vector<double*> blocks = {e.data(), cb.data(), cc.data()};
  for (auto& z : zeros) blocks.push_back(z.data());
  // Columns of the Jacobian in `names` order (drop the dummy columns of empty bases).
  auto columns = [&](const Eigen::MatrixXd& Jfull) {
    Eigen::MatrixXd J(Jfull.rows(), n_par);
    int c = 0, src = 0;
    J.middleCols(c, 8) = Jfull.middleCols(src, 8), c += 8, src += 8;
    if (nb > 0) J.middleCols(c, nb) = Jfull.middleCols(src, nb), c += nb;
    src += static_cast<int>(cb.size());
    if (nc > 0) J.middleCols(c, nc) = Jfull.middleCols(src, nc), c += nc;
    src += static_cast<int>(cc.size());
    J.rightCols(n_par - c) = Jfull.rightCols(Jfull.cols() - src);
    return J;
  };

  // Observability at the start point (readings are linear in the um-sized errors): fix one
  // parameter per invisible combination so that the solver cannot wander along it.
  const Eigen::MatrixXd J0 = columns(evaluate_jacobian(problem, blocks));
  Eigen::VectorXd scales(n_par);
  for (int j = 0; j < n_par; ++j) scales[j] = plausible_magnitude(units[static_cast<std::size_t>(j)]);
  const Observability obs = analyse_observability(J0, scales, options.observability_min_chi2);
  std::vector<bool> free(static_cast<std::size_t>(n_par), true);
  for (int j : obs.to_fix) free[static_cast<std::size_t>(j)] = false;
  // `free` is in `names` order: location errors, B map, C map, then the zeros set-up by set-up.
  std::vector<std::pair<double*, int>> sized = {{e.data(), 8}};
  if (nb > 0) sized.emplace_back(cb.data(), nb);  // empty bases are constant already
  if (nc > 0) sized.emplace_back(cc.data(), nc);
  for (auto& z : zeros) sized.emplace_back(z.data(), 3);
  hold_fixed(problem, sized, free, manifolds);

  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = options.max_iterations;
  so.function_tolerance = 1e-12;
  so.parameter_tolerance = 1e-12;
  so.gradient_tolerance = 1e-14;
  so.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);

  RtestJointIdentification out;
  out.converged = summary.IsSolutionUsable() && summary.termination_type == ceres::CONVERGENCE;
  out.iterations = static_cast<int>(summary.iterations.size()) - 1;
  out.n_samples = session.samples.size();

  Eigen::VectorXd r;
  const Eigen::MatrixXd J = columns(evaluate_jacobian(problem, blocks, &r));
  out.residuals.resize(session.samples.size());
  double ss = 0.0;
  for (std::size_t i = 0; i < session.samples.size(); ++i) {
    out.residuals[i] = -r.segment<3>(3 * static_cast<Eigen::Index>(i)) * sigma_mm;
    ss += out.residuals[i].squaredNorm();
  }
  const double n_res = 3.0 * static_cast<double>(session.samples.size());
  out.residual_rms_um = std::sqrt(ss / n_res) * 1e3;
  int n_free = 0;
  for (bool f : free) n_free += f;
  const double s2_mm = ss / std::max(n_res - n_free, 1.0);
  out.sigma_um = std::sqrt(s2_mm) * 1e3;
  out.covariance = covariance_from_jacobian(J, free, s2_mm / (sigma_mm * sigma_mm));

  Eigen::VectorXd values(n_par);
  values.head<8>() = e;
  for (int j = 0; j < nb; ++j) values[8 + j] = cb[static_cast<std::size_t>(j)];
  for (int j = 0; j < nc; ++j) values[8 + nb + j] = cc[static_cast<std::size_t>(j)];
  for (std::size_t k = 0; k < zeros.size(); ++k) {
    values.segment<3>(n_model + 3 * static_cast<Eigen::Index>(k)) = zeros[k];
    out.probe_zeros[setups[k]] = zeros[k];
  }
  for (int j = 0; j < n_par; ++j) {
    ParameterEstimate p;
    p.name = names[static_cast<std::size_t>(j)];
    p.unit = units[static_cast<std::size_t>(j)];
    p.value = values[j];
    p.std = std::sqrt(std::max(0.0, out.covariance(j, j)));
    p.observable = obs.observable[static_cast<std::size_t>(j)];
    out.parameters.push_back(p);
  }
  for (std::size_t k = 0; k < obs.null_space.size(); ++k)
    out.unobservable.push_back(obs.describe(static_cast<int>(k), names, units));

  out.model.machine = session.machine;
  out.model.basis = basis;
  out.model.params = values.head(n_model);
  out.model.covariance = out.covariance.topLeftCorner(n_model, n_model);
  out.model.observable.assign(obs.observable.begin(), obs.observable.begin() + n_model);

  out.notes.push_back("probe zero per set-up fitted: no reading is assumed to be zero");
  out.notes.push_back(
      "B map: even powers of B for translations, odd for rotations (separates it from the B "
      "axis' location errors); C map: harmonics 1.." + std::to_string(basis.c_harmonics) +
      " of C, polynomial of degree " + std::to_string(basis.c_b_degree) + " in B");
  if (!basis.gamma_cb) out.notes.push_back("gamma_CB not fitted (assumed zero, as Oyama Sec. 4.2)");
  out.notes.push_back("rotary zero offsets E_B0B, E_C0C are not in the model: an R-test with the "
                      "probe zero unknown cannot see a constant C offset; E_B0B acts as E_B0C");
  if (!out.converged) out.notes.push_back("Ceres did not converge: " + summary.message);
  return out;
}

}  // namespace rotacal

// SPDX-License-Identifier: BSD-3-Clause
// GUM / ISO/TR 230-9 uncertainty budget of the identified location errors: type A from the
// noise model, type B from the catalogue effects the final model leaves out.
#include "rotacal/diagnose/uncertainty_budget.hpp"

#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>

#include "budget_detail.hpp"
#include "rotacal/core/error.hpp"
#include "rotacal/core/stats.hpp"
#include "rotacal/kinematics/parameter_blocks.hpp"
#include "scoring.hpp"

namespace rotacal {

using diagnosis_detail::free_columns;

std::vector<double> plausible_sizes(const Effect& e, const PlausibleSizes& z, double duration_s) {
  const double T = std::max(duration_s, 1.0);
  std::vector<double> a(static_cast<std::size_t>(e.num_params()), 0.0);
  switch (e.kind) {
    case EffectKind::ballbar_length_offset:
      a = {z.bar_length_mm};
      break;
    case EffectKind::ballbar_thermal_drift:
      a = {z.drift_mm / T};
      break;
    case EffectKind::tool_offset_Z:
      a = {z.tool_length_mm};
      break;
    case EffectKind::rotary_zero_offset:
      a = {z.rotary_zero_rad};
      break;
    case EffectKind::angular_positioning:
      a = {z.angular_positioning_rad, z.angular_positioning_rad};
      break;
    case EffectKind::radial_motion:
      a.assign(4, z.error_motion_mm);
      break;
    case EffectKind::axial_motion:
      a.assign(2, z.error_motion_mm);
      break;
    case EffectKind::tilt_motion:
      a.assign(4, z.tilt_motion_rad);
      break;
    case EffectKind::gravity_sag:
      a = {z.gravity_sag_mm};
      break;
    case EffectKind::coning:
      a = {z.coning};
      break;
    case EffectKind::linear_squareness:
      a = {z.squareness_rad};
      break;
    case EffectKind::linear_scale:
      a = {z.scale};
      break;
    case EffectKind::thermal_drift:
      a = {z.drift_mm / T};
      break;
    case EffectKind::thermal_warmup:
      a = {z.warmup_mm, 0.0};
      break;  // tau moves nothing at d = 0
    case EffectKind::straightness: {
      // c_k u^k reaches the deviation at the end of the length: u = length / 2 / 100 mm.
      const double u = z.straightness_length_mm / 200.0;
      a = {z.straightness_mm / (u * u), z.straightness_mm / (u * u * u),
           z.straightness_mm / (u * u * u * u)};
      break;
    }
    case EffectKind::tool_offset:
      a = {z.tool_offset_mm};
      break;
    case EffectKind::linear_pitch:
      a = {z.angular_error_rad, z.angular_error_rad};
      break;
    case EffectKind::rotary_backlash:
      a = {z.backlash_rad};
      break;
    case EffectKind::servo_lag:
      a = {z.servo_lag_s};
      break;
    case EffectKind::reversal_spike:
      a = {z.reversal_spike_rad, 0.0};
      break;  // tau moves nothing at h = 0
    case EffectKind::stylus_radius_offset:
      a = {z.stylus_radius_mm};
      break;
    case EffectKind::probe_lobing:
      a = {z.probe_lobing_mm, z.probe_lobing_mm};
      break;
  }
  const auto names = e.param_names();
  const auto it = z.overrides.find(e.id());
  for (std::size_t k = 0; k < a.size(); ++k) {
    if (it != z.overrides.end()) a[k] = it->second;
    const auto one = z.overrides.find(e.id() + "." + names[k]);
    if (one != z.overrides.end()) a[k] = one->second;
    if (!(a[k] >= 0.0) || !std::isfinite(a[k]))
      throw InvalidArgument("plausible size of " + e.id() + "." + names[k] + " is " +
                            std::to_string(a[k]) + ": must be finite and >= 0");
  }
  return a;
}

void budget_detail::check_inputs(const PlausibleSizes& sizes, const std::vector<Effect>& all,
                                 double coverage) {
  if (!(coverage > 0.0 && coverage < 1.0))
    throw InvalidArgument("uncertainty_budget: coverage is " + std::to_string(coverage) +
                          ", must be in (0, 1)");
  for (const auto& [key, value] : sizes.overrides) {
    (void)value;
    const Effect e = Effect::parse(key.substr(0, key.find('.')));
    if (std::find(all.begin(), all.end(), e) == all.end())
      throw InvalidArgument("uncertainty_budget: override '" + key +
                            "' names no candidate of this session");
  }
}

UncertaintyBudget uncertainty_budget(const DiagnosisProblem& P, const Diagnosis& D,
                                     const PlausibleSizes& sizes, double coverage, int max_harmonic,
                                     std::size_t design_rows) {
  const std::vector<Effect> all = P.candidates(max_harmonic);
  budget_detail::check_inputs(sizes, all, coverage);
  const ModelFit& fit = D.final_fit;
  if (fit.residuals.size() == 0 || fit.jacobian.rows() != fit.residuals.size())
    throw InvalidArgument("uncertainty_budget: the diagnosis has no final fit");
  std::vector<Effect> candidates;  // what the final model leaves out
  for (const Effect& c : all)
    if (std::find(fit.effects.effects.begin(), fit.effects.effects.end(), c) ==
        fit.effects.effects.end())
      candidates.push_back(c);
  const budget_detail::BudgetedFit model{P.machine(),         fit,     D.noise,
                                         D.baseline.noise_um, nullptr, P.times()};
  return budget_detail::budget_of(
      model, candidates,
      [&](const budget_detail::JacobianVisitor& v) {
        P.visit_candidate_jacobians_reduced(fit, candidates, design_rows, v);
      },
      sizes, coverage);
}

namespace {

// The session's own bound on a left-out effect where it sees it: the linearised estimate on the
// final (whitened) residuals with the model projected out, |value| + 2 sigma. Replaces the
// half-widths `a` where that is tighter; false where the session does not determine the effect
// or the bound is no tighter.
bool tighten_by_session(const Eigen::MatrixXd& perp_w, const Eigen::VectorXd& r_w,
                        std::vector<double>& a) {
  // perp_w = Q R: the SVD of the small R and Q^T r_w give what the SVD of perp_w would (its
  // singular values and V, the estimate), without forming perp_w's n x p U, which cost the most
  // of a long session's budget.
  const Eigen::Index p = perp_w.cols();
  if (p == 0 || perp_w.rows() < p) return false;
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(perp_w);
  const Eigen::MatrixXd R = qr.matrixQR().topRows(p).triangularView<Eigen::Upper>();
  const Eigen::VectorXd qt_r = (qr.householderQ().transpose() * r_w).head(p);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::VectorXd s = svd.singularValues();
  if (s[s.size() - 1] <= 1e-9 * std::max(1.0, s[0])) return false;
  const Eigen::VectorXd est = svd.solve(qt_r);
  const Eigen::MatrixXd cov =
      svd.matrixV() * s.cwiseInverse().cwiseAbs2().asDiagonal() * svd.matrixV().transpose();
  bool tighter = false;
  std::vector<double> bound(a.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    bound[k] = std::abs(est[i]) + 2.0 * std::sqrt(cov(i, i));
    tighter = tighter || bound[k] < a[k];
  }
  if (!tighter) return false;
  for (std::size_t k = 0; k < a.size(); ++k) a[k] = std::min(a[k], bound[k]);
  return true;
}

// (J_w^T J_w)^-1 by J_w = Q R in place, then the SVD of the small R: J_w's singular values and
// V, without the SVD's own two n x f copies (352 MB of a 1,000,000-reading session's budget).
Eigen::MatrixXd gls_covariance(Eigen::MatrixXd J_w) {
  const Eigen::HouseholderQR<Eigen::Ref<Eigen::MatrixXd>> qr_w(J_w);
  const Eigen::Index f = J_w.cols();
  const Eigen::MatrixXd R_w =
      J_w.rows() >= f ? Eigen::MatrixXd(qr_w.matrixQR().topRows(f).triangularView<Eigen::Upper>())
                      : Eigen::MatrixXd(qr_w.matrixQR().triangularView<Eigen::Upper>());
  Eigen::JacobiSVD<Eigen::MatrixXd> svd_w(R_w, Eigen::ComputeThinV);
  Eigen::VectorXd inv_s = svd_w.singularValues();
  for (Eigen::Index i = 0; i < inv_s.size(); ++i)
    inv_s[i] = inv_s[i] > 1e-12 * inv_s[0] ? 1.0 / inv_s[i] : 0.0;
  return svd_w.matrixV() * inv_s.cwiseAbs2().asDiagonal() * svd_w.matrixV().transpose();
}

}  // namespace

UncertaintyBudget budget_detail::budget_of(const BudgetedFit& m,
                                           const std::vector<Effect>& candidates,
                                           const CandidateJacobians& jacobians,
                                           const PlausibleSizes& sizes, double coverage) {
  const ModelFit& fit = m.fit;
  const auto n = fit.residuals.size();
  ROTACAL_ASSERT(fit.jacobian.rows() == n);
  const auto& times = m.times;
  const double duration = times.empty() ? 0.0
                                        : *std::max_element(times.begin(), times.end()) -
                                              *std::min_element(times.begin(), times.end());

  // Whitening by the fit's noise model (white: 1/sigma).
  std::unique_ptr<ArWhitener> W;
  if (!m.noise.white() && m.noise.n == static_cast<std::size_t>(n))
    W = std::make_unique<ArWhitener>(m.noise);
  const double sigma_mm = std::max(m.noise_um, 1e-9) * 1e-3;
  const auto whiten = [&](const Eigen::MatrixXd& M) {
    Eigen::MatrixXd out = M;
    if (W)
      W->apply(out);
    else
      out /= sigma_mm;
    return out;
  };

  // Free columns and where the location errors sit among them.
  std::vector<Eigen::Index> free_index(static_cast<std::size_t>(fit.jacobian.cols()), -1);
  Eigen::Index nf = 0;
  for (Eigen::Index j = 0; j < fit.jacobian.cols(); ++j)
    if (fit.jacobian.col(j).squaredNorm() > 0.0) free_index[static_cast<std::size_t>(j)] = nf++;
  const Eigen::MatrixXd J = free_columns(fit.jacobian);
  // Type A: the fit's own covariance where it has one (the identification's, as it reports it),
  // else the GLS covariance (J_w^T J_w)^-1 by SVD (free parameters are determined: no null space).
  Eigen::MatrixXd cov_a;
  if (m.covariance) {
    ROTACAL_ASSERT(m.covariance->rows() == fit.jacobian.cols());
    std::vector<Eigen::Index> cols;
    for (Eigen::Index j = 0; j < fit.jacobian.cols(); ++j)
      if (free_index[static_cast<std::size_t>(j)] >= 0) cols.push_back(j);
    cov_a = (*m.covariance)(cols, cols);
  } else {
    cov_a = gls_covariance(whiten(J));
  }
  const double n_eff = W ? m.noise.effective_samples : static_cast<double>(n);
  const double dof_a = std::max(1.0, n_eff - static_cast<double>(J.cols()));
  // Unweighted least squares (what the fits do): bias = pinv(J) J_effect delta, by J's thin Q
  // formed once: each candidate then costs two products with it, where a decomposition's solve
  // applies every reflector to the candidate's n rows.
  std::optional<Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>> ls;  // J rank-deficient
  Eigen::MatrixXd Q_j, R_j;  // J P = Q_j R_j; the decomposition itself released
  Eigen::PermutationMatrix<Eigen::Dynamic> P_j;
  {
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr_j(J);
    if (qr_j.rank() < J.cols()) {
      ls.emplace(J);
    } else {
      Q_j = qr_j.householderQ() * Eigen::MatrixXd::Identity(J.rows(), J.cols());
      R_j = qr_j.matrixR().topLeftCorner(J.cols(), J.cols()).triangularView<Eigen::Upper>();
      P_j = qr_j.colsPermutation();
    }
  }
  const auto bias_of = [&](const Eigen::MatrixXd& Jc) -> Eigen::MatrixXd {
    if (ls) return ls->solve(Jc);
    const Eigen::MatrixXd c = Q_j.transpose() * Jc;
    return P_j * R_j.triangularView<Eigen::Upper>().solve(c);
  };
  const Eigen::VectorXd r_w = whiten(fit.residuals);

  struct Contribution {
    std::string effect, basis;
    Eigen::VectorXd
        bias;  // per free parameter, at the half-widths (RSS over the effect's parameters)
    Eigen::VectorXd u;
    double dof;
    std::vector<double> a;
  };
  std::vector<Contribution> lines(candidates.size());
  std::size_t visited = 0;
  jacobians([&](std::size_t i, const Eigen::MatrixXd& Jc) {
    ROTACAL_ASSERT(i < candidates.size() && Jc.rows() == n);
    ++visited;
    const Effect& c = candidates[i];
    const Eigen::MatrixXd B = bias_of(Jc);  // d(free params) / d(effect params)
    std::vector<double> a = plausible_sizes(c, sizes, duration);
    // The session's own bound where it sees the effect, where it is tighter.
    const bool bounded = sizes.use_session_bounds && tighten_by_session(whiten(Jc - J * B), r_w, a);
    Contribution L;
    L.effect = c.id();
    L.basis = bounded ? "session bound" : "default plausible size";
    L.dof = bounded ? dof_a : std::numeric_limits<double>::infinity();
    const Eigen::Map<const Eigen::VectorXd> av(a.data(), static_cast<Eigen::Index>(a.size()));
    const Eigen::MatrixXd per = B * av.asDiagonal();  // bias of each parameter at each half-width
    L.bias = per.rowwise().norm();
    L.u = L.bias / std::sqrt(3.0);  // rectangular
    L.a = a;
    lines[i] = std::move(L);
  });
  ROTACAL_ASSERT(visited == candidates.size());

  UncertaintyBudget out;
  out.coverage = coverage;
  ParameterLayout location;  // the location errors' names and units, as every problem lays them out
  const ParameterBlock errors = add_location_errors(location, m.machine);
  for (std::size_t i = 0; i < errors.names.size(); ++i) {
    LocationBudget L;
    L.name = errors.names[i];
    L.unit = errors.units[i];
    const auto p = std::find_if(fit.parameters.begin(), fit.parameters.end(),
                                [&](const ParameterEstimate& q) { return q.name == L.name; });
    const auto col = p == fit.parameters.end()
                         ? -1
                         : free_index[static_cast<std::size_t>(p - fit.parameters.begin())];
    if (col < 0 || !p->observable) {
      L.observable = false;
      out.errors.push_back(L);
      continue;
    }
    L.value = p->value;
    L.u_a = std::sqrt(std::max(0.0, cov_a(col, col)));
    L.dof_a = dof_a;
    double uc2 = L.u_a * L.u_a, ws = std::pow(L.u_a, 4) / dof_a;
    for (const Contribution& c : lines) {
      BudgetLine b;
      b.effect = c.effect;
      b.basis = c.basis;
      b.u = c.u[col];
      b.bias_at_size = c.bias[col];
      b.dof = c.dof;
      b.half_width = c.a;
      uc2 += b.u * b.u;
      if (std::isfinite(b.dof)) ws += std::pow(b.u, 4) / b.dof;
      L.type_b.push_back(b);
    }
    std::sort(L.type_b.begin(), L.type_b.end(),
              [](const BudgetLine& a, const BudgetLine& b) { return a.u > b.u; });
    L.u_c = std::sqrt(uc2);
    L.nu_eff = ws > 0.0 ? std::pow(L.u_c, 4) / ws : std::numeric_limits<double>::infinity();
    L.k = stats::t_coverage(coverage, L.nu_eff);
    L.expanded = L.k * L.u_c;
    for (const BudgetLine& b : L.type_b)
      if (b.u * b.u >= 0.1 * uc2) L.dominant.push_back(b.effect);
    out.errors.push_back(std::move(L));
  }
  return out;
}

}  // namespace rotacal

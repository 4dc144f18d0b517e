// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The one joint-fit driver: parameters with names, units and plausible scales -> observability
/// -> Gauss-Newton solve -> covariance -> ParameterEstimate list. The ballbar joint fit, the
/// R-test joint fit and the diagnosis' refits all call `solve_joint`.
///
/// A model hands the driver its residuals (model - measured, in the measurement's unit, e.g. mm)
/// and their Jacobian over contiguous arrays, all samples in one call (`ResidualModel`).
/// `evaluate_with_jets` derives both from one templated per-sample function of the kinematics,
/// so no second hand-written copy of a model exists.
///
/// Weights. Without a whitener every residual is divided by `sigma` (the declared noise):
/// chi-square and observability are in units of that sigma, and the covariance is
/// (J^T J)^-1 s^2 with s^2 the residual variance (so a wrong declared sigma does not bias it).
/// With a ResidualWhitener W (core/whitener.hpp; it maps residuals in the measurement's unit to
/// independent unit-variance ones) the fit minimises |W r|^2 (GLS), the covariance is
/// (Jw^T Jw)^-1 without rescaling, and the summary reports the whitened chi2/dof.

#include <ceres/jet.h>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "rotacal/core/error.hpp"
#include "rotacal/core/estimate.hpp"
#include "rotacal/core/least_squares.hpp"
#include "rotacal/core/whitener.hpp"

namespace rotacal {

/// Residuals of a model over all its samples at once.
class ResidualModel {
 public:
  virtual ~ResidualModel() = default;
  virtual Eigen::Index num_residuals() const = 0;
  virtual int num_parameters() const = 0;
  /// r = model - measured at x (num_residuals values, measurement units). If J is not null,
  /// also J = d model / d x (num_residuals x num_parameters, already sized by the caller).
  virtual void evaluate(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> r,
                        Eigen::MatrixXd* J) const = 0;
  /// Samples (each with rows_per_item() residuals, consecutive).
  virtual Eigen::Index num_items() const { return num_residuals(); }
  virtual int rows_per_item() const { return 1; }
  /// The same for samples 0, stride, 2 stride, ... only (r and J resized here), for a cheap
  /// start on long sessions. Returns false if the model does not offer it.
  virtual bool evaluate_subset(const Eigen::VectorXd& /*x*/, Eigen::Index /*stride*/,
                               Eigen::VectorXd& /*r*/, Eigen::MatrixXd* /*J*/) const {
    return false;
  }
};

/// One unknown of a fit.
struct FitParameter {
  std::string name;
  std::string unit;
  double start = 0.0;
  /// Plausible magnitude for observability (0: plausible_magnitude(unit)).
  double scale = 0.0;
  /// Held at `start` whatever the data say (e.g. the coefficient of an empty basis).
  bool held = false;
  /// Where it trades off against parameters that do not yield, it takes only the part they
  /// cannot express (core/yield_convention.hpp): set for catalogue effects fitted on top of a
  /// baseline, so that a partly shared effect leaves both determined.
  bool yields = false;
};

struct JointFitSettings {
  int max_iterations = 100;
  /// A direction is unobservable when moving along it by plausible magnitudes changes
  /// chi-square by less than this (core/least_squares.hpp).
  double observability_min_chi2 = 1.0;
  /// Declared 1 sigma of one residual, measurement units (scales chi-square when there is no
  /// whitener; the covariance uses the residual variance then).
  double sigma = 1.0;
  /// Optional GLS whitener; its size() must equal the number of residuals.
  std::shared_ptr<const ResidualWhitener> whitener;
  /// Stop when no free parameter moves by more than this fraction of its 1 sigma.
  double step_tolerance_sigma = 1e-6;
  /// Accept a solution reached with a Jacobian from an earlier point while the shift that stale
  /// Jacobian can leave is below this many sigma; 0: always end on a Jacobian evaluated at the
  /// solution (small fits that must reach the minimum to round-off, fit/orthogonal_distance).
  double stale_jacobian_sigma = 1e-2;
};

struct JointFitOutcome {
  Eigen::VectorXd values;                    ///< solution, in parameter order
  std::vector<ParameterEstimate> estimates;  ///< one per parameter, in order
  Eigen::MatrixXd covariance;                ///< 1 sigma^2, zero rows/cols for fixed ones
  Eigen::VectorXd residuals;                 ///< measured - model at the solution
  Eigen::MatrixXd jacobian;                  ///< d model / d parameter at the solution
                                             ///< (unweighted, measurement units)
  std::vector<bool> free;                    ///< per parameter: estimated (not held or fixed)
  Observability observability;               ///< at the start point
  /// x_reported = convention * x_solved (p x p; empty: none): the yield convention of the
  /// parameters with FitParameter::yields. A refit of the same model applies it too.
  Eigen::MatrixXd convention;
  std::vector<std::string> unobservable;  ///< null directions in words
  double residual_variance = 0.0;         ///< s^2 used for the covariance (1 when whitened)
  FitSummary summary;
};

/// [Long sessions: Gauss-Newton on every k-th sample, for a start near the solution] ->
/// observability (fix one parameter per invisible combination) -> Gauss-Newton with step
/// control -> covariance at the solution -> estimates. Throws InvalidArgument for
/// fewer residuals than free parameters, a whitener of the wrong size, or a non-finite
/// residual at the start (naming the first bad residual).
JointFitOutcome solve_joint(const ResidualModel& model, const std::vector<FitParameter>& parameters,
                            const JointFitSettings& settings = {});

/// Refits of the same model after its measurements changed (Monte Carlo draws): every refit
/// starts at the reference solution and reuses its Jacobian, free set and normal equations
/// (chord Gauss-Newton, residuals only). A draw's solution lies a few sigma from the
/// reference, where the Jacobian differs by ~sigma/scale (1e-6 relative for um errors on a
/// 100 mm set-up), so the chord converges in two or three residual evaluations to the same
/// point as a fresh fit. A refit that does not contract falls back to solve_joint.
class JointRefitter {
 public:
  JointRefitter(const JointFitOutcome& reference, std::vector<FitParameter> parameters,
                JointFitSettings settings);
  struct Result {
    Eigen::VectorXd values;
    bool converged = false;
    int residual_evaluations = 0;
    bool fell_back = false;  ///< solve_joint was needed
  };
  /// `model` must have the reference's residual and parameter layout.
  Result refit(const ResidualModel& model) const;

 private:
  Eigen::VectorXd start_;
  std::vector<FitParameter> parameters_;
  JointFitSettings settings_;
  std::vector<Eigen::Index> idx_;  // free parameters
  Eigen::MatrixXd Jw_free_;        // weighted Jacobian of the free parameters
  Eigen::LDLT<Eigen::MatrixXd> ldlt_;
  Eigen::VectorXd sigma_;       // 1 sigma of each free parameter (chi2 units)
  Eigen::MatrixXd convention_;  // the reference's yield convention (empty: none)
};

// ------------------------------------------------------------------ Jets over batches

namespace detail {
// One forward-mode pass of width K over parameters [c0, c0 + K): f(i, x, out) for every item
// i, its `rows` outputs into r (first pass only) and into the columns of J.
template <int K, typename F>
void jet_pass(const F& f, Eigen::Index n_items, int rows, const Eigen::VectorXd& x, int c0,
              double* r, Eigen::MatrixXd& J) {
  using Jet = ceres::Jet<double, K>;
  const int p = static_cast<int>(x.size());
  const int width = std::min(K, p - c0);
  std::vector<Jet> xj(static_cast<std::size_t>(p));
  for (int j = 0; j < p; ++j) xj[static_cast<std::size_t>(j)] = Jet(x[j]);
  for (int c = 0; c < width; ++c) xj[static_cast<std::size_t>(c0 + c)].v[c] = 1.0;
  Jet out[8];
  for (Eigen::Index i = 0; i < n_items; ++i) {
    f(i, xj.data(), out);
    for (int k = 0; k < rows; ++k) {
      const Eigen::Index row = i * rows + k;
      if (r) r[row] = out[k].a;
      for (int c = 0; c < width; ++c) J(row, c0 + c) = out[k].v[c];
    }
  }
}
}  // namespace detail

/// Residuals (and, if J is not null, their Jacobian) of `n_items` samples with `rows` (<= 8)
/// outputs each, from one generic function f(Eigen::Index i, const T* x, T* out) called with
/// T = double for residuals alone and T = ceres::Jet<double, K> for derivatives (passes of
/// width K = 4, 8, 12 or 16 over the parameters; f must write `rows` values of model - measured).
template <typename F>
void evaluate_with_jets(const F& f, Eigen::Index n_items, int rows, const Eigen::VectorXd& x,
                        Eigen::Ref<Eigen::VectorXd> r, Eigen::MatrixXd* J) {
  ROTACAL_ASSERT(rows >= 1 && rows <= 8);
  ROTACAL_ASSERT(r.size() == n_items * rows);
  if (!J) {
    double out[8];
    for (Eigen::Index i = 0; i < n_items; ++i) {
      f(i, x.data(), out);
      for (int k = 0; k < rows; ++k) r[i * rows + k] = out[k];
    }
    return;
  }
  const int p = static_cast<int>(x.size());
  ROTACAL_ASSERT(J->rows() == n_items * rows && J->cols() == p);
  // The narrowest Jet that holds all parameters in one pass; wider fits take passes of 16.
  for (int c0 = 0; c0 < std::max(p, 1); c0 += 16) {
    double* rr = c0 == 0 ? r.data() : nullptr;
    const int left = p - c0;
    if (left <= 4)
      detail::jet_pass<4>(f, n_items, rows, x, c0, rr, *J);
    else if (left <= 8)
      detail::jet_pass<8>(f, n_items, rows, x, c0, rr, *J);
    else if (left <= 12)
      detail::jet_pass<12>(f, n_items, rows, x, c0, rr, *J);
    else
      detail::jet_pass<16>(f, n_items, rows, x, c0, rr, *J);
  }
}

}  // namespace rotacal

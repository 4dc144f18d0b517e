// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The diagnosis of a ballbar session: the DiagnosisProblem for the exact ballbar model,
/// baseline = location errors + actual pivot (identify_joint with no effects).

#include <memory>

#include "rotacal/ballbar/identify.hpp"
#include "rotacal/core/whitener.hpp"
#include "rotacal/diagnose/diagnosis.hpp"
#include "rotacal/diagnose/uncertainty_budget.hpp"
#include "rotacal/session/session.hpp"

namespace rotacal {

namespace diagnosis_detail {
class BallbarPlacesCache;
}

class BallbarDiagnosisProblem : public DiagnosisProblem {
 public:
  /// `reference` is a complete standard test for the same machine (commanded rows; lengths
  /// unused), used to name the test that separates two ambiguous candidates; may be empty.
  explicit BallbarDiagnosisProblem(BallbarSession session, BallbarSession reference = {});
  /// Optional noise model for every fit (GLS, core/joint_fit.hpp): one residual per sample.
  std::shared_ptr<const ResidualWhitener> whitener;

  MachineType machine() const override { return session_.machine; }

  std::string instrument() const override { return "ballbar"; }
  const std::vector<std::string>& groups() const override { return arrays_.test; }
  const std::vector<double>& times() const override { return times_; }
  const std::vector<RotaryAngles<double>>& angles() const override { return arrays_.angles; }
  std::optional<double> declared_noise_um() const override { return session_.noise_um; }
  Eigen::Vector3d mean_commanded_xyz() const override {
    return rotacal::mean_commanded_xyz(session_.samples);
  }
  std::vector<Effect> candidates(int max_harmonic) const override;
  ModelFit fit(const EffectModel& effects) const override { return fit_gls(effects, whitener); }
  ModelFit fit_gls(const EffectModel& effects,
                   std::shared_ptr<const ResidualWhitener> noise) const override;
  Eigen::MatrixXd candidate_jacobian(const ModelFit& at, const Effect& candidate) const override;
  std::vector<Eigen::MatrixXd> candidate_jacobians(
      const ModelFit& at, const std::vector<Effect>& candidates) const override;
  void visit_candidate_jacobians(
      const ModelFit& at, const std::vector<Effect>& candidates,
      const std::function<void(std::size_t, const Eigen::MatrixXd&)>& visit) const override;
  void visit_candidate_jacobians_reduced(
      const ModelFit& at, const std::vector<Effect>& candidates, std::size_t rows,
      const std::function<void(std::size_t, const Eigen::MatrixXd&)>& visit) const override;
  /// The candidate's Jacobian by Jets of all its parameters, without the harmonic shortcut
  /// (tests compare the two).
  Eigen::MatrixXd candidate_jacobian_by_jets(const ModelFit& at, const Effect& candidate) const;
  std::vector<std::string> reference_groups() const override;
  Eigen::MatrixXd reference_jacobian(const ModelFit& at, const Effect& candidate,
                                     std::vector<std::string>* row_groups) const override;

  /// The identification behind the last call to fit().
  const BallbarSession& session() const { return session_; }

 private:
  Eigen::MatrixXd jacobian_on(const std::vector<BallbarSample>& samples,
                              const std::vector<RotaryMotion>& motion, const ModelFit& at,
                              const Effect& candidate) const;
  BallbarSession session_;
  BallbarArrays arrays_;  // the samples as arrays, built once for every refit
  BallbarSession reference_;
  std::vector<RotaryMotion> reference_motion_;
  std::vector<double> times_;  // arrays_.time as the interface's vector (labels and angles are
                               // arrays_'s own: every row of the session, in order)
  // Where each candidate enters the session's rows, which no fit changes (src/diagnose/
  // ballbar_sensitivities.hpp): computed once per session, shared by copies of the problem.
  std::shared_ptr<diagnosis_detail::BallbarPlacesCache> places_;
};

/// Diagnose a ballbar session (see diagnosis.hpp). The session is taken by value: pass
/// std::move(session) when it is not needed afterwards (a 10-minute 1 kHz recording holds about
/// 70 MB of samples, which the diagnosis would otherwise copy).
Diagnosis diagnose_ballbar(BallbarSession session, const DiagnosisOptions& options = {},
                           BallbarSession reference = {});

/// The diagnosis an uncertainty budget of `session` rests on (uncertainty_budget.hpp). A session
/// of more than 2 `design_rows` readings is searched on every k-th reading, k = ceil(n /
/// design_rows), and only what that search found is then diagnosed on every reading, which gives
/// the final fit, noise model and noise level the budget reads (the search scores every
/// candidate on every reading: 1.4 of 1.8 CPU-s at 90,000 readings). A shorter session:
/// diagnose_ballbar as it is. A long session's search sees a tenth of the readings, so an effect
/// it does not name is a type B line at its plausible size or session bound.
Diagnosis budget_diagnosis_ballbar(const BallbarSession& session,
                                   const DiagnosisOptions& options = {},
                                   std::size_t design_rows = kBudgetDesignRows);

}  // namespace rotacal

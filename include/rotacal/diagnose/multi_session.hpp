// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// One diagnosis of several sessions of one machine (issue 50 item 1): ballbar, R-test and
/// touch-probe sessions diagnosed together by the one engine (diagnosis.hpp), each through its
/// instrument's DiagnosisProblem.
///
/// The sessions are stacked into one DiagnosisProblem:
///  - machine effects (location errors, rotary zero offsets, the table and axis entries, the
///    linear-axis entries, the effects of motion) have ONE set of parameters shared by every
///    session whose instrument models them;
///  - instrument, set-up and time effects (ballbar length offset and drift, stylus radius
///    offset, lobing, tool offsets, thermal drift and warm-up: each session has its own clock)
///    are the session's: their Effect::session is its name, their id "name:id", and so are its
///    nuisance parameters (pivot, sphere, probe zeros), named "name:parameter";
///  - each session's readings are weighted by the reference noise over its own (declared, else
///    from successive differences of its baseline residuals), so that a white treatment with
///    one sigma weighs each instrument by its noise; the engine's noise model then has one
///    stream per session and group (group names "name:group", times on each session's clock)
///    and each session its own AR coefficients (NoiseModelOptions::pool_by_session).
///
/// The joint fit of a model: each session's own nonlinear fit of the effects it models, then one
/// linear (GLS) step on their stacked Jacobians to the shared parameters' common value. The
/// sessions' values of a shared parameter differ by um/urad-sized amounts, where the model is
/// linear far below the noise (as the engine's linearised scoring assumes, diagnosis.hpp).

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "rotacal/diagnose/diagnosis.hpp"

namespace rotacal {

struct BallbarSession;
struct RtestSession;
struct ProbeSession;

/// One session of a diagnosis of several: its name (how its effects and parameters are
/// prefixed) and its instrument's problem. Build with the factories.
struct DiagnosisSession {
  std::string name;
  std::shared_ptr<const DiagnosisProblem> problem;
  /// The touches of a touch-probe session (else null): a session too short to be fitted alone
  /// joins an earlier one of the same sphere as its continuation (diagnose_sessions).
  std::shared_ptr<const ProbeSession> probe;

  static DiagnosisSession of(std::string name, BallbarSession session);
  static DiagnosisSession of(std::string name, RtestSession session);
  static DiagnosisSession of(std::string name, ProbeSession session);
};

/// True for an effect of the machine (one parameter set for every session); false for one of
/// an instrument, a set-up or a session's clock.
bool is_machine_effect(const Effect& e);

/// The sessions stacked as one problem of the engine (see the file comment).
class MultiDiagnosisProblem : public DiagnosisProblem {
 public:
  /// Throws InvalidArgument for no session, repeated or empty names (or a name
  /// with ':'), or sessions of different machines (naming them).
  explicit MultiDiagnosisProblem(std::vector<DiagnosisSession> sessions);

  MachineType machine() const override { return machine_; }
  /// The first session's instrument: the design command a finding points to is run --after one
  /// session.
  std::string instrument() const override { return sessions_.front().problem->instrument(); }
  const std::vector<std::string>& groups() const override { return groups_; }
  const std::vector<double>& times() const override { return times_; }
  const std::vector<RotaryAngles<double>>& angles() const override { return angles_; }
  std::optional<double> declared_noise_um() const override { return declared_; }
  std::vector<Effect> candidates(int max_harmonic) const override;
  ModelFit fit(const EffectModel& effects) const override { return fit_gls(effects, nullptr); }
  ModelFit fit_gls(const EffectModel& effects,
                   std::shared_ptr<const ResidualWhitener> noise) const override;
  Eigen::MatrixXd candidate_jacobian(const ModelFit& at, const Effect& candidate) const override;
  std::vector<Eigen::MatrixXd> candidate_jacobians(
      const ModelFit& at, const std::vector<Effect>& candidates) const override;
  Eigen::Vector3d mean_commanded_xyz() const override { return mean_xyz_; }
  double correlation_bound_z() const override { return correlation_bound_z_; }

  std::size_t num_sessions() const { return sessions_.size(); }
  const DiagnosisSession& session(std::size_t k) const { return sessions_[k]; }
  /// Session k's readings: rows [offset, offset + rows) of the stacked ones.
  Eigen::Index offset(std::size_t k) const { return offsets_[k]; }
  Eigen::Index rows(std::size_t k) const { return offsets_[k + 1] - offsets_[k]; }
  /// The factor on session k's readings (reference noise / its noise).
  double weight(std::size_t k) const { return weights_[k]; }
  /// Session k's noise (um): declared, else from successive differences of its baseline.
  double noise_um(std::size_t k) const { return noise_um_[k]; }

 private:
  // Session k's share of a joint model: the machine effects its instrument models and its own.
  EffectModel share(std::size_t k, const EffectModel& joint) const;
  // Session k's nonlinear fit of share(k, joint), kept per model.
  const ModelFit& session_fit(std::size_t k, const EffectModel& share) const;
  // The joint name of each parameter of session k's fit `f` of `share`: location errors and
  // machine effects' as they are, the session's own prefixed "name:".
  std::vector<std::string> joint_names(std::size_t k, const EffectModel& share,
                                       const ModelFit& f) const;
  bool models(std::size_t k, const Effect& machine_effect) const;

  std::vector<DiagnosisSession> sessions_;
  MachineType machine_ = MachineType::AC_trt;
  std::vector<std::string> groups_;
  std::vector<double> times_;
  std::vector<RotaryAngles<double>> angles_;
  std::optional<double> declared_;
  std::vector<Eigen::Index> offsets_;
  std::vector<double> weights_, noise_um_;
  Eigen::Vector3d mean_xyz_ = Eigen::Vector3d::Zero();
  double correlation_bound_z_ = 0.0;
  mutable std::vector<std::map<std::string, ModelFit>> fits_;  // per session, by model id
  mutable std::vector<std::map<std::string, bool>> models_;    // per session, by effect id
};

/// A diagnosis of several sessions: the engine's over the stacked readings (its RMS and
/// residuals in the weighted units of the first session's noise), and each session's share.
struct MultiDiagnosis {
  Diagnosis diagnosis;
  struct Session {
    std::string name, instrument;
    std::size_t n = 0;           ///< its readings
    double noise_um = 0.0;       ///< declared, else from successive differences
    double weight = 1.0;         ///< the factor on its readings in the joint problem
    double rms_before_um = 0.0;  ///< baseline residual RMS of its readings, um
    double rms_after_um = 0.0;   ///< after the findings (joint final model), um
  };
  std::vector<Session> sessions;  ///< in input order
  /// Where finding i holds: "machine" or the name of its session.
  std::vector<std::string> where;
  /// What was done to a session before the diagnosis: a touch-probe session with fewer touches
  /// than its own unknowns (the one-pose added test `design probe --after S` may propose) is not
  /// fitted alone but joined to the earlier probe session of the same sphere, as its
  /// continuation (the design's assumption: the sphere stays on the table).
  std::vector<std::string> notes;
};

/// Diagnose several sessions of one machine together. Throws as MultiDiagnosisProblem does, for
/// fewer than two sessions, and for a probe session too short to be fitted alone with no
/// earlier probe session of the same sphere (nominal centre and diameters) to continue.
MultiDiagnosis diagnose_sessions(std::vector<DiagnosisSession> sessions,
                                 const DiagnosisOptions& options = {});

}  // namespace rotacal
